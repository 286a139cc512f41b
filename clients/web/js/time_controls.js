// Date, time and a time-of-day slider, all UTC, edit clock.utc (only the clock: in ephemeris
// mode the daemon places the sun and moon, in manual mode they stay where the sliders put them).
// The daemon's clock runs at clock.time_scale, so the simulated time shown here follows the
// frame headers (and stats) live; a field being typed in or a slider being dragged is left
// alone, and frames older than the last accepted set do not pull the fields back.

import { clearErrors, showReplyError } from "./field_errors.js";

const THROTTLE_MS = 200;
const pad = (n) => String(n).padStart(2, "0");

// "2026-06-21T12:00:05Z" for Unix seconds (whole seconds, rounded down).
export function isoSeconds(unixSeconds) {
  return new Date(Math.floor(unixSeconds) * 1000).toISOString().replace(/\.\d{3}Z$/, "Z");
}

export class TimeControls {
  constructor(sendSet) {
    this.sendSet = sendSet;
    this.date = document.getElementById("date");
    this.time = document.getElementById("time");
    this.slider = document.getElementById("time-of-day");
    this.output = document.getElementById("time-of-day-out");
    this.clock = document.getElementById("sim-clock");
    this.dragging = false;
    this.timer = null;
    this.minRevision = 0; // frames before the last accepted set show the old time
    this.date.addEventListener("change", () => this.send(this.composeFromInputs()));
    this.time.addEventListener("change", () => this.send(this.composeFromInputs()));
    this.slider.addEventListener("input", () => {
      this.time.value = this.sliderTime();
      this.output.textContent = this.time.value.slice(0, 5);
      if (this.timer === null)
        this.timer = setTimeout(() => { this.timer = null; this.send(this.composeFromInputs()); },
                                THROTTLE_MS);
    });
    this.slider.addEventListener("change", () => {
      this.time.value = this.sliderTime();
      this.send(this.composeFromInputs());
    });
    this.slider.addEventListener("pointerdown", () => { this.dragging = true; });
    this.slider.addEventListener("pointerup", () => { this.dragging = false; });
  }

  sliderTime() {
    const minutes = Number(this.slider.value);
    return `${pad(Math.floor(minutes / 60))}:${pad(minutes % 60)}:00`;
  }

  composeFromInputs() {
    const time = this.time.value.length === 5 ? `${this.time.value}:00` : this.time.value;
    return `${this.date.value}T${time}Z`;
  }

  async send(utc) {
    const reply = await this.sendSet({ clock: { utc } });
    if (reply.type === "error") {
      showReplyError(reply, "clock.utc");
    } else {
      clearErrors(["clock.utc"]);
      if (typeof reply.revision === "number") this.minRevision = reply.revision;
    }
  }

  // The simulated clock from a frame header (with its state revision) or stats (revision null).
  tick(unixSeconds, revision) {
    if (!Number.isFinite(unixSeconds)) return;
    if (revision !== null && revision < this.minRevision) return;
    this.show(isoSeconds(unixSeconds));
  }

  update(state) {
    if (state.clock && typeof state.clock.utc === "string") this.show(state.clock.utc);
  }

  show(utc) {
    const match = /^(\d{4}-\d{2}-\d{2})T(\d{2}):(\d{2}):(\d{2})/.exec(utc);
    if (!match) return;
    const text = `${match[1]} ${match[2]}:${match[3]}:${match[4]} UTC`;
    if (this.clock.textContent !== text) this.clock.textContent = text;
    if (document.activeElement !== this.date) this.date.value = match[1];
    if (document.activeElement !== this.time) this.time.value = `${match[2]}:${match[3]}:${match[4]}`;
    if (this.dragging || this.timer !== null) return;
    this.slider.value = String(Number(match[2]) * 60 + Number(match[3]));
    this.output.textContent = `${match[2]}:${match[3]}`;
  }
}

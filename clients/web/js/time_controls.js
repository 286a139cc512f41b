// Date, time and a time-of-day slider, all UTC, edit clock.utc (only the clock: in ephemeris
// mode the daemon places the sun and moon, in manual mode they stay where the sliders put them).
// The daemon's clock runs at clock.time_scale, so the simulated time shown here follows the
// frame headers (and stats) live; a field being typed in or a slider being dragged is left
// alone, and neither frames older than the last accepted set nor any arriving while a set is
// on its way pull the fields back.

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
    this.inFlight = 0; // sets sent and not yet answered
    this.date.addEventListener("change", () => this.send(this.composeFromInputs()));
    this.time.addEventListener("change", () => this.send(this.composeFromInputs()));
    // The throttled and the final send both carry the slider's time, composed when it moved:
    // the time field follows the running clock, so reading it when the timer fires could send
    // the time a frame showed meanwhile instead of the one chosen.
    this.slider.addEventListener("input", () => {
      this.time.value = this.sliderTime();
      this.output.textContent = this.time.value.slice(0, 5);
      this.pendingUtc = this.composeFromSlider();
      if (this.timer === null)
        this.timer = setTimeout(() => { this.timer = null; this.send(this.pendingUtc); },
                                THROTTLE_MS);
    });
    this.slider.addEventListener("change", () => {
      this.cancelThrottled();
      this.time.value = this.sliderTime();
      this.send(this.composeFromSlider());
    });
    this.slider.addEventListener("pointerdown", () => { this.dragging = true; });
    this.slider.addEventListener("pointerup", () => { this.dragging = false; });
  }

  sliderTime() {
    const minutes = Number(this.slider.value);
    return `${pad(Math.floor(minutes / 60))}:${pad(minutes % 60)}:00`;
  }

  composeFromSlider() {
    return `${this.date.value}T${this.sliderTime()}Z`;
  }

  cancelThrottled() {
    if (this.timer === null) return;
    clearTimeout(this.timer);
    this.timer = null;
  }

  composeFromInputs() {
    const time = this.time.value.length === 5 ? `${this.time.value}:00` : this.time.value;
    return `${this.date.value}T${time}Z`;
  }

  async send(utc) {
    this.inFlight++;
    let reply;
    try {
      reply = await this.sendSet({ clock: { utc } });
    } finally {
      this.inFlight--;
    }
    if (reply.type === "error") {
      showReplyError(reply, "clock.utc");
    } else {
      clearErrors(["clock.utc"]);
      if (typeof reply.revision === "number") this.minRevision = reply.revision;
    }
  }

  // The simulated clock from a frame header (with its state revision) or stats (revision null).
  tick(unixSeconds, revision) {
    if (!Number.isFinite(unixSeconds) || this.inFlight > 0) return;
    if (revision !== null && revision < this.minRevision) return;
    this.show(isoSeconds(unixSeconds));
  }

  update(state) {
    if (this.inFlight > 0) return;
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

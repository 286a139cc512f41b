// Date, time and a time-of-day slider, all UTC, edit clock.utc. While clock.sky_bodies is
// "manual" the same `set` also moves the sun to where it stands at that time and place
// (sun_position.js), so the sky follows the clock before and after the server's ephemeris.

import { clearErrors, showReplyError } from "./field_errors.js";
import { sunPosition } from "./sun_position.js";

const THROTTLE_MS = 200;
const pad = (n) => String(n).padStart(2, "0");

export class TimeControls {
  constructor(sendSet) {
    this.sendSet = sendSet;
    this.date = document.getElementById("date");
    this.time = document.getElementById("time");
    this.slider = document.getElementById("time-of-day");
    this.output = document.getElementById("time-of-day-out");
    this.state = null;
    this.dragging = false;
    this.timer = null;
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

  // The set for an ISO 8601 UTC time: the clock, and the sun in manual mode.
  patchFor(utc) {
    const patch = { clock: { utc } };
    const when = new Date(utc);
    if (this.state && this.state.clock.sky_bodies === "manual" && !Number.isNaN(when.getTime())) {
      const sun = sunPosition(when, this.state.location.latitude_deg,
                              this.state.location.longitude_deg);
      patch.sun = { elevation_deg: Math.round(sun.elevationDeg * 1000) / 1000,
                    azimuth_deg: Math.round(sun.azimuthDeg * 1000) / 1000 };
    }
    return patch;
  }

  async send(utc) {
    const reply = await this.sendSet(this.patchFor(utc));
    if (reply.type === "error") showReplyError(reply, "clock.utc");
    else clearErrors(["clock.utc"]);
  }

  update(state) {
    this.state = state;
    const utc = state.clock && state.clock.utc;
    if (typeof utc !== "string" || this.dragging) return;
    const match = /^(\d{4}-\d{2}-\d{2})T(\d{2}):(\d{2}):(\d{2})/.exec(utc);
    if (!match) return;
    if (document.activeElement !== this.date) this.date.value = match[1];
    if (document.activeElement !== this.time) this.time.value = `${match[2]}:${match[3]}:${match[4]}`;
    this.slider.value = String(Number(match[2]) * 60 + Number(match[3]));
    this.output.textContent = `${match[2]}:${match[3]}`;
  }
}

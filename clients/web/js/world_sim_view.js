// What the daemon's world simulation moves on its own (the page hears of it through the
// simulation events its hello asks for): the sun and moon in ephemeris mode, whose sliders are
// then read-only, and a weather transition's progress (weather.transition.*, read-only).

import { setLock } from "./locks.js";

const $ = (id) => document.getElementById(id);
const SUN_SLIDERS = ["sun-elevation", "sun-azimuth"];

export class WorldSimView {
  constructor() {
    this.progress = $("weather-transition-progress");
    this.text = $("weather-transition-text");
    this.note = $("sun-mode-note");
    this.state = null;
  }

  update(state) {
    this.state = state;
    const ephemeris = state.clock && state.clock.sky_bodies === "ephemeris";
    for (const id of SUN_SLIDERS) setLock($(id), "ephemeris", ephemeris);
    this.note.textContent = ephemeris
      ? "The server places the sun and moon for the clock and location."
      : "Set the sun by hand; the clock does not move it.";
    const t = state.weather && state.weather.transition;
    if (!t) return;
    const progress = Math.min(1, Math.max(0, Number(t.progress)));
    this.progress.value = progress;
    if (!(t.duration_s > 0)) this.text.textContent = "none";
    else if (progress >= 1) this.text.textContent = `done (${t.duration_s} s from ${t.start})`;
    else this.text.textContent = `${Math.round(progress * 100)} % of ${t.duration_s} s`;
  }

  // The state changes without events: while the clock runs, or a transition is under way.
  running() {
    const s = this.state;
    if (!s) return false;
    const clockRuns = s.clock && s.clock.time_scale > 0;
    const t = s.weather && s.weather.transition;
    return Boolean(clockRuns || (t && t.duration_s > 0 && t.progress < 1));
  }
}

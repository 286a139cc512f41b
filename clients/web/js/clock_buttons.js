// Play, pause and now for the simulated clock: pause sets clock.time_scale to 0, play back to
// the last non-zero scale the state had (1 when none was seen), now sets clock.utc to this
// computer's time. The buttons carry data-controller, so a viewer sees them disabled.

import { clearErrors, showReplyError } from "./field_errors.js";
import { isoSeconds } from "./time_controls.js";

const $ = (id) => document.getElementById(id);

export class ClockButtons {
  constructor(sendSet) {
    this.sendSet = sendSet;
    this.lastRunningScale = 1;
    this.scale = null;
    $("clock-play").addEventListener("click",
      () => this.send({ time_scale: this.lastRunningScale }, "clock.time_scale"));
    $("clock-pause").addEventListener("click",
      () => this.send({ time_scale: 0 }, "clock.time_scale"));
    $("clock-now").addEventListener("click",
      () => this.send({ utc: isoSeconds(Date.now() / 1000) }, "clock.utc"));
  }

  async send(clock, errorKey) {
    const reply = await this.sendSet({ clock });
    if (reply.type === "error") showReplyError(reply, errorKey);
    else clearErrors([errorKey]);
  }

  update(state) {
    const scale = state.clock && state.clock.time_scale;
    if (typeof scale !== "number" || scale === this.scale) return;
    this.scale = scale;
    if (scale > 0) this.lastRunningScale = scale;
    $("clock-play").setAttribute("aria-pressed", String(scale > 0));
    $("clock-pause").setAttribute("aria-pressed", String(scale === 0));
    $("clock-state").textContent = scale > 0 ? `running at ${scale}×` : "paused";
  }
}

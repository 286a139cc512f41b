// Controls bound to world-state fields by `data-path` ("clouds.low.coverage"): a change sends
// `set` with that one field; a state from the server updates every control the user is not
// touching. `data-kind`: "number" (default), "rgb" (one value for all three channels) or "enum".

import { clearErrors, showReplyError } from "./field_errors.js";

const THROTTLE_MS = 200; // sliders send at most 5 sets per second while dragged

export function patchFor(path, value) {
  const patch = {};
  let node = patch;
  const parts = path.split(".");
  parts.slice(0, -1).forEach((part) => { node = node[part] = {}; });
  node[parts[parts.length - 1]] = value;
  return patch;
}

export function valueAt(state, path) {
  return path.split(".").reduce((node, part) => (node == null ? undefined : node[part]), state);
}

function formatNumber(value) {
  if (!Number.isFinite(value)) return String(value);
  const magnitude = Math.abs(value);
  if (magnitude !== 0 && (magnitude < 0.01 || magnitude >= 1e5)) return value.toExponential(2);
  return String(Math.round(value * 1000) / 1000);
}

export class WorldControls {
  // sendSet(patch, errorKeys) resolves with the server's reply.
  constructor(root, sendSet) {
    this.sendSet = sendSet;
    this.controls = [...root.querySelectorAll("[data-path]")];
    this.busy = new Set(); // controls being dragged: the server's state does not move them
    this.timers = new Map();
    this.seen = new Map(); // the server's last value per control, as text
    for (const control of this.controls) {
      const path = control.dataset.path;
      if (control.type === "range") {
        control.addEventListener("input", () => { this.showOutput(control); this.throttled(control); });
        control.addEventListener("pointerdown", () => this.busy.add(control));
        control.addEventListener("pointerup", () => this.busy.delete(control));
      }
      // The change sends the final value; a throttled send still pending would repeat it
      // after a state poll may have put the server's older value back in the control.
      control.addEventListener("change", () => {
        this.cancelThrottled(control);
        this.send(control);
      });
      control.setAttribute("aria-describedby", `${control.id}-hint`);
      const hint = document.createElement("span");
      hint.id = `${control.id}-hint`;
      hint.className = "visually-hidden";
      hint.textContent = `world state field ${path}`;
      control.after(hint);
    }
  }

  read(control) {
    const kind = control.dataset.kind || "number";
    if (kind === "enum") return control.value;
    const text = control.value.trim();
    return text === "" ? NaN : Number(text);
  }

  showOutput(control) {
    const out = document.querySelector(`output[data-output-for="${control.dataset.path}"]`);
    if (out) out.textContent = formatNumber(Number(control.value));
  }

  throttled(control) {
    if (this.timers.has(control)) return;
    this.timers.set(control, setTimeout(() => {
      this.timers.delete(control);
      this.send(control);
    }, THROTTLE_MS));
  }

  cancelThrottled(control) {
    if (!this.timers.has(control)) return;
    clearTimeout(this.timers.get(control));
    this.timers.delete(control);
  }

  async send(control) {
    const path = control.dataset.path;
    const value = this.read(control);
    if (typeof value === "number" && !Number.isFinite(value)) return; // emptied, or not a number yet
    const reply = await this.sendSet(patchFor(path, value));
    if (reply.type === "error") showReplyError(reply, path);
    else clearErrors([path]);
  }

  // Shows a `state` message's values where the server's value changed since the last state
  // (the state is polled while the simulation runs: a value the user typed, refused or not,
  // stays until the server's changes), except in a control being typed in or dragged.
  update(state) {
    for (const control of this.controls) {
      const typing = control === document.activeElement && control.tagName === "INPUT"
        && control.type !== "range";
      if (typing || this.busy.has(control)) continue;
      let value = valueAt(state, control.dataset.path);
      if (Array.isArray(value)) value = value[0];
      if (value === undefined || this.seen.get(control) === String(value)) continue;
      this.seen.set(control, String(value));
      control.value = String(value);
      this.showOutput(control);
    }
  }
}

// Preset pickers (`[data-preset-kind]` selects with an Apply button each): filled from the
// server's list_presets for that kind; a kind the server does not know shows its error instead.
// The weather kind takes an optional transition time.

import { clearErrors, showError, showReplyError } from "./field_errors.js";
import { setLock } from "./locks.js";

const $ = (id) => document.getElementById(id);

export class Presets {
  constructor(request) {
    this.request = request;
    this.selects = [...document.querySelectorAll("select[data-preset-kind]")];
    for (const button of document.querySelectorAll("button[data-apply-kind]"))
      button.addEventListener("click", () => this.apply(button.dataset.applyKind));
  }

  async refresh() {
    for (const select of this.selects) {
      const kind = select.dataset.presetKind;
      const reply = await this.request({ type: "list_presets", kind });
      const key = `preset:${kind}`;
      if (reply.type !== "presets" || !Array.isArray(reply.names)) {
        select.replaceChildren();
        setLock(select, "no-presets", true);
        if (reply.type === "error") showError(key, `${reply.message || reply.code} (${reply.code})`);
        continue;
      }
      const current = select.value;
      select.replaceChildren(...reply.names.map((name) => new Option(name, name)));
      if (reply.names.includes(current)) select.value = current;
      setLock(select, "no-presets", reply.names.length === 0);
      clearErrors([key]);
    }
  }

  async apply(kind) {
    const select = this.selects.find((s) => s.dataset.presetKind === kind);
    const key = `preset:${kind}`;
    if (!select || !select.value) {
      showError(key, "no preset to apply");
      return;
    }
    const message = { type: "apply_preset", kind, name: select.value };
    if (kind === "weather") {
      const seconds = $("weather-transition").value.trim();
      if (seconds !== "" && Number(seconds) !== 0) message.transition_s = Number(seconds);
    }
    const reply = await this.request(message);
    if (reply.type === "error") showReplyError(reply, key);
    else clearErrors([key]);
  }
}

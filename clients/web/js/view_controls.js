// This client's view: camera (drag on the image to look, wheel to zoom, an altitude slider from
// the ground to 100000 km), exposure, size and frame rate. These are members of the
// subscription's view object, not of the world state, so a viewer may change them too; every
// change re-subscribes. Until the camera is touched the view follows the world's camera.

import { bindLookDrag, clamp, wrapDegrees } from "./look_drag.js";

const $ = (id) => document.getElementById(id);
const ALTITUDE_MAX_KM = 100000;

// Slider 0..1000 to altitude: 0 m, 9 m at 125, 10 km at 500, 1000 km at 750, 100000 km at 1000.
export function altitudeFromSlider(s) {
  return 0.001 * (10 ** (s * 8 / 1000) - 1);
}
export function sliderFromAltitude(km) {
  return Math.round(1000 * Math.log10(km / 0.001 + 1) / 8);
}
function formatAltitude(km) {
  return km < 1 ? `${Math.round(km * 1000)} m` : `${km < 100 ? km.toFixed(1) : Math.round(km)} km`;
}

export class ViewControls {
  constructor(canvas, onChange) {
    this.canvas = canvas;
    this.onChange = onChange;
    this.camera = null; // null: follow the world state's camera
    this.shown = { altitude_km: 0.2, yaw_deg: 180, pitch_deg: 10, fov_deg: 70 };
    this.bindSlider("camera-altitude", (v) => ({ altitude_km: altitudeFromSlider(v) }));
    this.bindSlider("camera-yaw", (v) => ({ yaw_deg: v }));
    this.bindSlider("camera-pitch", (v) => ({ pitch_deg: v }));
    this.bindSlider("camera-fov", (v) => ({ fov_deg: v }));
    $("camera-follow").addEventListener("click", () => { this.camera = null; this.onChange(); });
    for (const id of ["exposure-mode", "exposure-ev", "exposure-compensation", "view-size",
                      "view-fps", "view-format"]) {
      $(id).addEventListener("change", () => { this.showOutputs(); this.onChange(); });
      $(id).addEventListener("input", () => this.showOutputs());
    }
    this.bindPointer();
    this.showCamera();
    this.showOutputs();
  }

  bindSlider(id, toCamera) {
    $(id).addEventListener("input", () => {
      this.setCamera(toCamera(Number($(id).value)), id);
    });
  }

  bindPointer() {
    bindLookDrag(this.canvas, () => this.shown, (change) => this.setCamera(change), [1, 170]);
    this.canvas.addEventListener("keydown", (e) => {
      const step = { ArrowLeft: [-5, 0], ArrowRight: [5, 0], ArrowUp: [0, 5], ArrowDown: [0, -5] }[e.key];
      if (!step) return;
      e.preventDefault();
      this.setCamera({ yaw_deg: wrapDegrees(this.shown.yaw_deg + step[0]),
                       pitch_deg: clamp(this.shown.pitch_deg + step[1], -90, 90) });
    });
  }

  setCamera(change, fromSlider) {
    this.shown = { ...this.shown, ...change };
    this.camera = { ...this.shown };
    this.showCamera(fromSlider);
    this.onChange();
  }

  showCamera(skipSlider) {
    const c = this.shown;
    const set = (id, value, text) => {
      if (id !== skipSlider) $(id).value = String(value);
      $(`${id}-out`).textContent = text;
    };
    set("camera-altitude", sliderFromAltitude(c.altitude_km), formatAltitude(c.altitude_km));
    set("camera-yaw", Math.round(wrapDegrees(c.yaw_deg)), `${Math.round(wrapDegrees(c.yaw_deg))}°`);
    set("camera-pitch", Math.round(c.pitch_deg), `${Math.round(c.pitch_deg)}°`);
    set("camera-fov", Math.round(c.fov_deg), `${Math.round(c.fov_deg)}°`);
    $("camera-follow").disabled = this.camera === null;
  }

  showOutputs() {
    $("exposure-ev-out").textContent = Number($("exposure-ev").value).toFixed(1);
    $("exposure-compensation-out").textContent = Number($("exposure-compensation").value).toFixed(1);
    const mode = $("exposure-mode").value;
    $("exposure-ev").disabled = mode !== "manual";
    $("exposure-compensation").disabled = mode !== "auto";
  }

  // The world state's camera is shown while the view follows it.
  update(state) {
    if (this.camera !== null || !state.camera) return;
    this.shown = { ...state.camera };
    this.showCamera();
  }

  // The subscription's view object (protocol/PROTOCOL.md, "The view object").
  view() {
    const [width, height] = $("view-size").value.split("x").map(Number);
    const view = { width, height, fps: Number($("view-fps").value),
                   format: $("view-format").value };
    if (this.camera) {
      view.camera = { ...this.camera,
                      altitude_km: clamp(Math.round(this.camera.altitude_km * 1e4) / 1e4, 0,
                                         ALTITUDE_MAX_KM) };
    }
    const mode = $("exposure-mode").value;
    if (mode === "manual") view.exposure = { mode, ev100: Number($("exposure-ev").value) };
    else if (mode === "auto")
      view.exposure = { mode, compensation_ev: Number($("exposure-compensation").value) };
    return view;
  }
}

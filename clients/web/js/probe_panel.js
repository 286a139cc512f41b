// The probe: a click on the live image (not a drag, which turns the camera) asks the server for
// the sky's luminance in that pixel's direction, from the view's camera; the illuminance on
// the ground from the sun and the sky follows the sun; the sun's and moon's positions come from
// the state. The probe computes the clear atmosphere (no clouds), as `skyd probe` does.

const $ = (id) => document.getElementById(id);
const RAD = Math.PI / 180;
const CLICK_SLOP_PX = 4;

// The direction (azimuth from north through east, elevation, degrees) of the pixel at (x, y)
// of a w x h pinhole image: the renderer's camera (shaders/include/camera.glsl), with the
// vertical field of view.
export function pixelDirection(x, y, w, h, camera) {
  const tanHalf = Math.tan(camera.fov_deg * RAD / 2);
  const nx = (2 * (x + 0.5) / w - 1) * tanHalf * (w / h);
  const ny = (1 - 2 * (y + 0.5) / h) * tanHalf;
  const yaw = camera.yaw_deg * RAD;
  const pitch = camera.pitch_deg * RAD;
  const forward = [Math.cos(pitch) * Math.sin(yaw), Math.cos(pitch) * Math.cos(yaw), Math.sin(pitch)];
  const right = [Math.cos(yaw), -Math.sin(yaw), 0];
  const up = [-Math.sin(pitch) * Math.sin(yaw), -Math.sin(pitch) * Math.cos(yaw), Math.cos(pitch)];
  const d = [0, 1, 2].map((i) => forward[i] + nx * right[i] + ny * up[i]); // east, north, up
  const length = Math.hypot(...d);
  return {
    azimuth_deg: ((Math.atan2(d[0], d[1]) / RAD) % 360 + 360) % 360,
    elevation_deg: Math.asin(d[2] / length) / RAD,
  };
}

const wrap180 = (d) => ((((d + 180) % 360) + 360) % 360) - 180;
function fmt(v) {
  const a = Math.abs(v);
  if (a === 0) return "0";
  if (a >= 1e7 || a < 1e-2) return v.toExponential(2);
  return a >= 100 ? String(Math.round(v)) : v.toPrecision(3);
}
const angle = (v) => `${v.toFixed(1)}°`;

export class ProbePanel {
  // cameraOf(): the view's camera as drawn (yaw, pitch, fov, altitude_km).
  constructor(canvas, request, cameraOf) {
    this.canvas = canvas;
    this.request = request;
    this.cameraOf = cameraOf;
    this.state = null;
    this.sunZenith = null;
    this.illuminanceBusy = false;
    let down = null;
    canvas.addEventListener("pointerdown", (e) => { down = { x: e.clientX, y: e.clientY }; });
    canvas.addEventListener("click", (e) => {
      if (down && Math.hypot(e.clientX - down.x, e.clientY - down.y) > CLICK_SLOP_PX) return;
      const box = canvas.getBoundingClientRect();
      this.probeAt((e.clientX - box.left) * canvas.width / box.width,
                   (e.clientY - box.top) * canvas.height / box.height);
    });
  }

  sun() {
    return this.state && this.state.sun;
  }

  async probeAt(x, y) {
    const sun = this.sun();
    if (!sun) return;
    const camera = this.cameraOf();
    const px = Math.floor(x);
    const py = Math.floor(y);
    const dir = pixelDirection(px, py, this.canvas.width, this.canvas.height, camera);
    $("probe-pixel").textContent =
      `(${px}, ${py}): azimuth ${angle(dir.azimuth_deg)}, elevation ${angle(dir.elevation_deg)}`;
    const reply = await this.request({
      type: "probe", quantity: "luminance",
      altitude_km: Math.min(100000, Math.max(0, camera.altitude_km)),
      view_zenith_deg: 90 - dir.elevation_deg,
      view_azimuth_deg: wrap180(dir.azimuth_deg - sun.azimuth_deg),
      sun_zenith_deg: 90 - sun.elevation_deg,
    });
    if (reply.type === "probe_result" && Array.isArray(reply.luminance)) {
      const [r, g, b] = reply.luminance;
      $("probe-luminance").textContent = `R ${fmt(r)}, G ${fmt(g)}, B ${fmt(b)} cd/m²`;
    } else {
      $("probe-luminance").textContent = `${reply.message || reply.code} (${reply.code})`;
    }
  }

  async refreshIlluminance() {
    const sun = this.sun();
    if (!sun || this.illuminanceBusy) return;
    const zenith = 90 - sun.elevation_deg;
    if (zenith === this.sunZenith) return;
    this.illuminanceBusy = true;
    try {
      const reply = await this.request({ type: "probe", quantity: "illuminance",
                                         sun_zenith_deg: zenith });
      if (reply.type === "probe_result") {
        this.sunZenith = zenith;
        $("probe-sun-lux").textContent = `${fmt(reply.sun_lux)} lx`;
        $("probe-sky-lux").textContent = `${fmt(reply.sky_lux)} lx`;
      }
    } finally {
      this.illuminanceBusy = false;
    }
  }

  update(state) {
    this.state = state;
    const show = (id, body) => {
      if (!body || typeof body.azimuth_deg !== "number") return;
      $(id).textContent = `azimuth ${angle(body.azimuth_deg)}, elevation ${angle(body.elevation_deg)}`;
    };
    show("probe-sun", state.sun);
    show("probe-moon", state.moon);
    this.refreshIlluminance();
  }
}

// A panorama to look around in without the server: one equirectangular snapshot of the whole
// sphere (the view's altitude and exposure), reprojected here into a pinhole view of its own
// that a drag turns and the wheel zooms. "Load" takes a new one (after the sky has changed).

import { clearErrors, showReplyError } from "./field_errors.js";
import { bindLookDrag, clamp } from "./look_drag.js";
import { fetchSnapshot } from "./snapshot.js";

const $ = (id) => document.getElementById(id);
const RAD = Math.PI / 180;

export class PanoramaView {
  // viewOf(): the page's view object, whose altitude and exposure the panorama takes;
  // cameraOf(): the camera as the page shows it (the world's while the view follows it).
  constructor(canvas, viewOf, cameraOf) {
    this.canvas = canvas;
    this.context = canvas.getContext("2d");
    this.viewOf = viewOf;
    this.cameraOf = cameraOf;
    this.source = null; // {width, height, data, yaw_deg}: the panorama's pixels
    this.look = { yaw_deg: 180, pitch_deg: 10, fov_deg: 70 };
    this.frame = null;
    $("panorama-load").addEventListener("click", () => this.load());
    this.bindPointer();
  }

  bindPointer() {
    bindLookDrag(this.canvas, () => this.look, (change) => this.turn(change), [10, 150]);
  }

  turn(change) {
    this.look = { ...this.look, ...change };
    this.look.yaw_deg = ((this.look.yaw_deg % 360) + 360) % 360;
    $("panorama-look").textContent = `toward ${Math.round(this.look.yaw_deg)}°, ` +
      `up ${Math.round(this.look.pitch_deg)}°, field ${Math.round(this.look.fov_deg)}°`;
    if (this.frame === null) this.frame = requestAnimationFrame(() => { this.frame = null; this.draw(); });
  }

  async load() {
    const view = this.viewOf();
    const [width, height] = $("panorama-size").value.split("x").map(Number);
    // Centred on the page's yaw, so that the panorama opens where the view looks.
    const yaw = this.cameraOf().yaw_deg;
    view.camera = { ...(view.camera || {}), yaw_deg: yaw };
    $("panorama-status").textContent = "rendering…";
    const result = await fetchSnapshot({ ...view, width, height, format: "png",
                                         projection: "equirectangular" });
    if (result.error) {
      $("panorama-status").textContent = "";
      showReplyError(result.error, "panorama");
      return;
    }
    clearErrors(["panorama"]);
    const image = await createImageBitmap(result.blob);
    const scratch = new OffscreenCanvas(image.width, image.height);
    const context = scratch.getContext("2d");
    context.drawImage(image, 0, 0);
    image.close();
    this.source = { width: scratch.width, height: scratch.height, yaw_deg: yaw,
                    data: context.getImageData(0, 0, scratch.width, scratch.height).data };
    $("panorama-status").textContent = `${width} × ${height}`;
    const { yaw_deg, pitch_deg, fov_deg } = this.cameraOf();
    this.turn({ yaw_deg, pitch_deg, fov_deg: clamp(fov_deg, 10, 150) });
  }

  // Each output pixel's direction (the renderer's pinhole), looked up in the panorama:
  // column from the azimuth relative to its centre, row from the elevation.
  draw() {
    const src = this.source;
    if (!src) return;
    const { width: w, height: h } = this.canvas;
    const out = this.context.createImageData(w, h);
    const tanHalf = Math.tan(this.look.fov_deg * RAD / 2);
    const yaw = this.look.yaw_deg * RAD;
    const pitch = this.look.pitch_deg * RAD;
    const sy = Math.sin(yaw), cy = Math.cos(yaw), sp = Math.sin(pitch), cp = Math.cos(pitch);
    const f = [cp * sy, cp * cy, sp], r = [cy, -sy, 0], u = [-sp * sy, -sp * cy, cp];
    const centre = src.yaw_deg * RAD;
    for (let y = 0; y < h; y++) {
      const ny = (1 - 2 * (y + 0.5) / h) * tanHalf;
      for (let x = 0; x < w; x++) {
        const nx = (2 * (x + 0.5) / w - 1) * tanHalf * (w / h);
        const dx = f[0] + nx * r[0] + ny * u[0];
        const dy = f[1] + nx * r[1] + ny * u[1];
        const dz = f[2] + ny * u[2];
        const azimuth = Math.atan2(dx, dy) - centre;
        const elevation = Math.atan2(dz, Math.hypot(dx, dy));
        // Bilinear between the four nearest texel centres, wrapping around in azimuth.
        const fx = (((azimuth / (2 * Math.PI) + 0.5) % 1 + 1) % 1) * src.width - 0.5;
        const fy = Math.min(src.height - 1, Math.max(0, (0.5 - elevation / Math.PI) * src.height - 0.5));
        const x0 = Math.floor(fx), y0 = Math.floor(fy);
        const tx = fx - x0, ty = fy - y0;
        const xa = (x0 + src.width) % src.width, xb = (x0 + 1) % src.width;
        const ya = y0 * src.width, yb = Math.min(src.height - 1, y0 + 1) * src.width;
        const o = (y * w + x) * 4;
        for (let c = 0; c < 3; c++) {
          const top = src.data[(ya + xa) * 4 + c] * (1 - tx) + src.data[(ya + xb) * 4 + c] * tx;
          const bottom = src.data[(yb + xa) * 4 + c] * (1 - tx) + src.data[(yb + xb) * 4 + c] * tx;
          out.data[o + c] = top * (1 - ty) + bottom * ty;
        }
        out.data[o + 3] = 255;
      }
    }
    this.context.putImageData(out, 0, 0);
  }
}

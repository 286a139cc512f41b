// A weather map of the user's own (set_weather_map): a PNG, or raw 8-bit RGBA texels with the
// width and height typed beside it. Its four channels are previewed, as the server will read
// them, before the upload; the server's refusal shows next to the button.

import { clearErrors, showError, showReplyError } from "./field_errors.js";
import { setLock } from "./locks.js";
import { decodePng, isPng } from "./png_decode.js";

const $ = (id) => document.getElementById(id);
const MAX_SIDE = 512;
// The canvases of the preview, in channel order r, g, b, a (protocol/PROTOCOL.md).
const CHANNEL_CANVASES = ["weather-map-low", "weather-map-high", "weather-map-type",
                          "weather-map-precipitation"];

export function base64(bytes) {
  let text = "";
  for (let i = 0; i < bytes.length; i += 0x8000)
    text += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(text);
}

export class WeatherMapPanel {
  constructor(request, onRevision) {
    this.request = request;
    this.onRevision = onRevision;
    this.message = null; // the set_weather_map to send, once a file is read
    this.upload = $("weather-map-upload");
    setLock(this.upload, "no-file", true);
    $("weather-map-file").addEventListener("change", () => this.load());
    for (const id of ["weather-map-width", "weather-map-height"])
      $(id).addEventListener("change", () => this.load());
    this.upload.addEventListener("click", () => this.send());
  }

  async load() {
    const file = $("weather-map-file").files[0];
    this.message = null;
    setLock(this.upload, "no-file", true);
    $("weather-map-status").textContent = "";
    if (!file) return;
    const bytes = new Uint8Array(await file.arrayBuffer());
    let map = null;
    let note = "";
    try {
      if (isPng(bytes)) {
        this.message = { type: "set_weather_map", format: "png", data: base64(bytes) };
        map = await decodePng(bytes);
      } else {
        map = this.raw(bytes);
        this.message = { type: "set_weather_map", format: "rgba8", width: map.width,
                         height: map.height, data: base64(bytes) };
      }
    } catch (e) {
      if (!this.message) {
        showError("weather-map", e.message);
        return;
      }
      note = e.message; // a PNG this page cannot preview: the server may still take it
    }
    clearErrors(["weather-map"]);
    if (map) this.preview(map);
    $("weather-map-status").textContent = map
      ? `${file.name}: ${map.width} × ${map.height}` : `${file.name}: ${note}`;
    setLock(this.upload, "no-file", false);
  }

  // Raw texels: the typed size, or a square one when the fields are empty.
  raw(bytes) {
    let width = Number($("weather-map-width").value);
    let height = Number($("weather-map-height").value);
    if (!width || !height) width = height = Math.round(Math.sqrt(bytes.length / 4));
    if (width > MAX_SIDE || height > MAX_SIDE)
      throw new Error(`a map is at most ${MAX_SIDE} × ${MAX_SIDE}`);
    if (width * height * 4 !== bytes.length)
      throw new Error(`${bytes.length} bytes are not ${width} × ${height} RGBA texels; ` +
                      "type the map's width and height");
    return { width, height, rgba: bytes };
  }

  preview({ width, height, rgba }) {
    CHANNEL_CANVASES.forEach((id, channel) => {
      const canvas = $(id);
      canvas.width = width;
      canvas.height = height;
      const context = canvas.getContext("2d");
      const image = context.createImageData(width, height);
      for (let i = 0; i < width * height; i++) {
        const v = rgba[4 * i + channel];
        image.data.set([v, v, v, 255], 4 * i);
      }
      context.putImageData(image, 0, 0);
    });
  }

  async send() {
    if (!this.message) return;
    setLock(this.upload, "sending", true);
    let reply;
    try {
      reply = await this.request(this.message);
    } finally {
      setLock(this.upload, "sending", false);
    }
    if (reply.type === "ack") {
      clearErrors(["weather-map"]);
      this.onRevision(reply.revision);
      $("weather-map-status").textContent = `uploaded: revision ${reply.revision}`;
    } else {
      showReplyError(reply, "weather-map");
    }
  }
}

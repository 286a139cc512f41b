// Saves one frame of this page's view as a file: its camera and exposure, in a format and a
// projection picked here, fetched from the HTTP API and handed to the browser through an
// <a download> on a blob URL. The link stays on the page until the next snapshot.

import { clearErrors, showReplyError } from "./field_errors.js";
import { fetchSnapshot } from "./snapshot.js";

const $ = (id) => document.getElementById(id);

// The formats the server encodes (the view object's `format`); a new one is one entry.
export const SNAPSHOT_FORMATS = [
  { format: "jpeg", label: "JPEG (quality 90)", suffix: "", extension: "jpg", quality: 90 },
  { format: "png", label: "PNG (8-bit sRGB, as shown)", suffix: "", extension: "png" },
  { format: "png16", label: "PNG (16-bit linear light)", suffix: "-linear16", extension: "png" },
];

const PROJECTIONS = {
  perspective: { label: "this view", size: (w, h) => [w, h] },
  // The whole sphere, 2:1, as many rows as the view has.
  equirectangular: { label: "panorama", size: (w, h) => [2 * h, h] },
};

function fileStamp(utc) {
  return (utc || new Date().toISOString()).replace(/\.\d+Z$/, "Z").replace(/[:]/g, "");
}

export class SnapshotPanel {
  // viewOf(): the page's view object; utcOf(): the simulated clock as text, for the name.
  constructor(viewOf, utcOf) {
    this.viewOf = viewOf;
    this.utcOf = utcOf;
    this.url = null;
    const select = $("snapshot-format");
    for (const f of SNAPSHOT_FORMATS) select.add(new Option(f.label, f.format));
    $("snapshot-save").addEventListener("click", () => this.save());
  }

  async save() {
    const entry = SNAPSHOT_FORMATS.find((f) => f.format === $("snapshot-format").value);
    const projection = $("snapshot-projection").value;
    const view = this.viewOf();
    const [width, height] = PROJECTIONS[projection].size(view.width, view.height);
    const button = $("snapshot-save");
    button.disabled = true;
    $("snapshot-status").textContent = "rendering…";
    let result;
    try {
      result = await fetchSnapshot({ ...view, width, height, format: entry.format,
                                     quality: entry.quality, projection });
    } finally {
      button.disabled = false;
    }
    if (result.error) {
      $("snapshot-status").textContent = "";
      showReplyError(result.error, "snapshot");
      return;
    }
    clearErrors(["snapshot"]);
    const name = `skyd-${fileStamp(this.utcOf())}-${projection}${entry.suffix}.${entry.extension}`;
    this.offer(result.blob, name);
    $("snapshot-status").textContent = `${width} × ${height}`;
  }

  offer(blob, name) {
    if (this.url) URL.revokeObjectURL(this.url);
    this.url = URL.createObjectURL(blob);
    const link = $("snapshot-link");
    link.href = this.url;
    link.download = name;
    link.textContent = `${name} (${Math.ceil(blob.size / 1024)} KiB)`;
    link.hidden = false;
    link.click();
  }
}

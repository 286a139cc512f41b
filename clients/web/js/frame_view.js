// Binary frames (protocol/PROTOCOL.md, "Binary frames"): the 48-byte header, then the PNG or
// JPEG, drawn on the canvas. Counts frames and the rate at which they arrive.

export const HEADER_BYTES = 48;
// The header's format codes: PNG, PNG16 (also a PNG file), JPEG.
const IMAGE_TYPES = { 1: "image/png", 2: "image/png", 3: "image/jpeg" };

export function readHeader(buffer) {
  if (buffer.byteLength < HEADER_BYTES) throw new Error("frame shorter than its header");
  const view = new DataView(buffer);
  const magic = String.fromCharCode(...new Uint8Array(buffer, 0, 4));
  if (magic !== "SKYF") throw new Error("not a skyd frame");
  if (view.getUint16(4, true) !== 1) throw new Error("unknown frame header version");
  const type = IMAGE_TYPES[view.getUint16(6, true)];
  if (!type) throw new Error("unknown frame format");
  const header = {
    type,
    frameNumber: Number(view.getBigUint64(8, true)),
    revision: Number(view.getBigUint64(16, true)),
    simulationTime: view.getFloat64(24, true),
    width: view.getUint32(32, true),
    height: view.getUint32(36, true),
    payloadLength: view.getUint32(40, true),
  };
  if (header.payloadLength !== buffer.byteLength - HEADER_BYTES)
    throw new Error("frame length disagrees with its header");
  return header;
}

export class FrameView {
  constructor(canvas, onFrame) {
    this.canvas = canvas;
    this.context = canvas.getContext("2d");
    this.onFrame = onFrame;
    this.count = 0;
    this.arrivals = [];
    this.drawing = Promise.resolve();
  }

  // Draws frames in arrival order; a frame's header is read before its image decodes.
  draw(buffer) {
    const header = readHeader(buffer);
    const image = new Blob([new Uint8Array(buffer, HEADER_BYTES, header.payloadLength)],
                           { type: header.type });
    const decoded = createImageBitmap(image);
    this.drawing = this.drawing.then(() => decoded).then((image) => {
      if (this.canvas.width !== header.width || this.canvas.height !== header.height) {
        this.canvas.width = header.width;
        this.canvas.height = header.height;
      }
      this.context.drawImage(image, 0, 0);
      image.close();
      this.count++;
      const now = performance.now();
      this.arrivals.push(now);
      this.arrivals = this.arrivals.filter((t) => now - t < 2000);
      this.onFrame(header, this.count, this.arrivals.length / 2);
    });
    return this.drawing;
  }
}

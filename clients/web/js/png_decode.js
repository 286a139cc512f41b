// A PNG's stored samples as 8-bit RGBA, read as set_weather_map reads a weather map: no gamma
// or colour-space conversion, 16-bit values rounded to 8 bits, alpha 0 where the file has no
// alpha channel. The browser's own decoders cannot serve here: a canvas keeps colours
// premultiplied by alpha, and a weather map's alpha is precipitation, 0 wherever it does not
// rain, which would wipe out the other three channels there. Interlaced files are refused.

const SIGNATURE = [137, 80, 78, 71, 13, 10, 26, 10];
const CHANNELS = { 0: 1, 2: 3, 3: 1, 4: 2, 6: 4 };

export function isPng(bytes) {
  return bytes.length >= 8 && SIGNATURE.every((b, i) => bytes[i] === b);
}

async function inflate(bytes) {
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate"));
  return new Uint8Array(await new Response(stream).arrayBuffer());
}

function paeth(a, b, c) {
  const p = a + b - c;
  const pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
  return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

// Undoes the per-row filters in place; returns the rows without their filter bytes.
function unfilter(data, height, rowBytes, bpp) {
  const out = new Uint8Array(height * rowBytes);
  for (let y = 0; y < height; y++) {
    const filter = data[y * (rowBytes + 1)];
    const src = y * (rowBytes + 1) + 1;
    const row = y * rowBytes;
    for (let i = 0; i < rowBytes; i++) {
      const x = data[src + i];
      const a = i >= bpp ? out[row + i - bpp] : 0;
      const b = y > 0 ? out[row - rowBytes + i] : 0;
      const c = i >= bpp && y > 0 ? out[row - rowBytes + i - bpp] : 0;
      let v;
      switch (filter) {
      case 0: v = x; break;
      case 1: v = x + a; break;
      case 2: v = x + b; break;
      case 3: v = x + ((a + b) >> 1); break;
      case 4: v = x + paeth(a, b, c); break;
      default: throw new Error(`bad PNG row filter ${filter}`);
      }
      out[row + i] = v & 255;
    }
  }
  return out;
}

export async function decodePng(bytes) {
  if (!isPng(bytes)) throw new Error("not a PNG file");
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  let header = null;
  let palette = null;
  let transparency = null;
  const idat = [];
  for (let at = 8; at + 12 <= bytes.length;) {
    const length = view.getUint32(at);
    const type = String.fromCharCode(...bytes.subarray(at + 4, at + 8));
    const body = bytes.subarray(at + 8, at + 8 + length);
    if (type === "IHDR") {
      header = { width: view.getUint32(at + 8), height: view.getUint32(at + 12),
                 depth: body[8], colour: body[9], interlace: body[12] };
    } else if (type === "PLTE") palette = body;
    else if (type === "tRNS") transparency = body;
    else if (type === "IDAT") idat.push(body);
    else if (type === "IEND") break;
    at += 12 + length;
  }
  if (!header || !idat.length) throw new Error("PNG without IHDR or IDAT");
  const { width, height, depth, colour } = header;
  if (header.interlace) throw new Error("interlaced PNG: no preview (the server still reads it)");
  const channels = CHANNELS[colour];
  if (!channels) throw new Error(`unknown PNG colour type ${colour}`);
  const bitsPerPixel = channels * depth;
  const rowBytes = Math.ceil(width * bitsPerPixel / 8);
  const joined = new Uint8Array(idat.reduce((n, c) => n + c.length, 0));
  idat.reduce((at, c) => { joined.set(c, at); return at + c.length; }, 0);
  const rows = unfilter(await inflate(joined), height, rowBytes, Math.max(1, bitsPerPixel >> 3));

  const maxSample = (1 << depth) - 1;
  const sample = (y, index) => { // the index-th sample of row y, scaled to 0..255
    const row = y * rowBytes;
    if (depth === 16) return Math.round(((rows[row + 2 * index] << 8) | rows[row + 2 * index + 1]) * 255 / 65535);
    if (depth === 8) return rows[row + index];
    const bit = index * depth;
    const raw = (rows[row + (bit >> 3)] >> (8 - depth - (bit & 7))) & maxSample;
    return colour === 3 ? raw : Math.round(raw * 255 / maxSample);
  };
  const rgba = new Uint8Array(width * height * 4);
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++) {
      const o = (y * width + x) * 4;
      const s = (c) => sample(y, x * channels + c);
      if (colour === 3) {
        const i = s(0);
        rgba.set([palette[3 * i], palette[3 * i + 1], palette[3 * i + 2],
                  transparency && i < transparency.length ? transparency[i] : 0], o);
      } else if (colour === 0) rgba.set([s(0), s(0), s(0), 0], o);
      else if (colour === 4) rgba.set([s(0), s(0), s(0), s(1)], o);
      else if (colour === 2) rgba.set([s(0), s(1), s(2), 0], o);
      else rgba.set([s(0), s(1), s(2), s(3)], o);
    }
  }
  return { width, height, rgba };
}

// Live view of skyd's stream: connects to the server that served this page, subscribes to one
// view the size of the canvas and draws each PNG frame; reconnects when the connection drops.
"use strict";

const HEADER_BYTES = 48;
const canvas = document.getElementById("view");
const context = canvas.getContext("2d");
const show = (id, text) => { document.getElementById(id).textContent = text; };

let frameTimes = [];
let retryDelayMs = 500;

function readHeader(buffer) {
  const view = new DataView(buffer);
  const magic = String.fromCharCode(...new Uint8Array(buffer, 0, 4));
  if (magic !== "SKYF" || view.getUint16(4, true) !== 1) throw new Error("not a skyd frame");
  return {
    frameNumber: Number(view.getBigUint64(8, true)),
    revision: Number(view.getBigUint64(16, true)),
    width: view.getUint32(32, true),
    height: view.getUint32(36, true),
    payloadLength: view.getUint32(40, true),
  };
}

async function drawFrame(buffer) {
  const header = readHeader(buffer);
  const png = new Blob([new Uint8Array(buffer, HEADER_BYTES, header.payloadLength)],
                       { type: "image/png" });
  const image = await createImageBitmap(png);
  context.drawImage(image, 0, 0, canvas.width, canvas.height);
  image.close();
  show("revision", String(header.revision));
  const now = performance.now();
  frameTimes.push(now);
  frameTimes = frameTimes.filter((t) => now - t < 2000);
  show("fps", (frameTimes.length / 2).toFixed(1));
}

function connect() {
  const scheme = location.protocol === "https:" ? "wss:" : "ws:";
  const socket = new WebSocket(`${scheme}//${location.host}/`);
  socket.binaryType = "arraybuffer";
  show("connection", "connecting");
  socket.onopen = () => {
    retryDelayMs = 500;
    show("connection", "connected");
    socket.send(JSON.stringify({
      type: "subscribe", id: "live",
      view: { width: canvas.width, height: canvas.height, fps: 15 },
    }));
  };
  socket.onmessage = (event) => {
    if (event.data instanceof ArrayBuffer) {
      drawFrame(event.data).catch((e) => show("error", e.message));
      return;
    }
    const message = JSON.parse(event.data);
    if (message.type === "hello") show("role", message.role);
    else if (message.type === "event" && message.event === "state_changed")
      show("revision", String(message.revision));
    else if (message.type === "error") show("error", `${message.code}: ${message.message}`);
  };
  socket.onclose = (event) => {
    show("connection", `closed (${event.code}${event.reason ? ": " + event.reason : ""}); retrying`);
    setTimeout(connect, retryDelayMs);
    retryDelayMs = Math.min(retryDelayMs * 2, 10000);
  };
}

connect();

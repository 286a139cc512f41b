// One WebSocket to the skyd that served this page: requests matched to replies by id,
// server-initiated messages and binary frames handed to callbacks, automatic reconnection
// with exponential back-off (0.5 s doubling to 10 s).

const REPLY_TIMEOUT_MS = 15000;

export class Connection {
  // handlers: onStatus(text, open), onOpen(), onMessage(msg) for messages without a waiting
  // request (hello, event, frame, ...), onBinary(ArrayBuffer).
  constructor(url, handlers) {
    this.url = url;
    this.handlers = handlers;
    this.socket = null;
    this.pending = new Map();
    this.nextId = 1;
    this.retryDelayMs = 500;
    this.connect();
  }

  get open() {
    return this.socket !== null && this.socket.readyState === WebSocket.OPEN;
  }

  connect() {
    const socket = new WebSocket(this.url);
    this.socket = socket;
    socket.binaryType = "arraybuffer";
    this.handlers.onStatus("connecting", false);
    socket.onopen = () => {
      this.retryDelayMs = 500;
      this.handlers.onStatus("connected", true);
      this.handlers.onOpen();
    };
    socket.onmessage = (event) => this.receive(event.data);
    socket.onclose = (event) => {
      if (this.socket !== socket) return;
      this.failPending("disconnected");
      const why = event.reason ? `${event.code}: ${event.reason}` : String(event.code);
      const delay = this.retryDelayMs;
      this.handlers.onStatus(`closed (${why}); retrying in ${(delay / 1000).toFixed(1)} s`,
                             false);
      this.retryDelayMs = Math.min(this.retryDelayMs * 2, 10000);
      setTimeout(() => this.connect(), delay);
    };
  }

  receive(data) {
    if (data instanceof ArrayBuffer) {
      this.handlers.onBinary(data);
      return;
    }
    let msg;
    try {
      msg = JSON.parse(data);
    } catch (e) {
      this.handlers.onMessage({ type: "error", code: "client", message: `bad JSON: ${e.message}` });
      return;
    }
    // A subscription's frame carries no id; a snapshot's frame does, and is not a reply.
    const waiting = msg.type !== "frame" && msg.id !== undefined && this.pending.get(msg.id);
    if (waiting) {
      this.pending.delete(msg.id);
      clearTimeout(waiting.timer);
      waiting.resolve(msg);
    } else {
      this.handlers.onMessage(msg);
    }
  }

  // Sends msg with a fresh id; resolves with the reply (an `error` reply included), or with a
  // local error {code: "disconnected" | "timeout"} when none can come.
  request(msg) {
    if (!this.open)
      return Promise.resolve({ type: "error", code: "disconnected", message: "not connected",
                               fields: [] });
    const id = this.nextId++;
    return new Promise((resolve) => {
      const timer = setTimeout(() => {
        this.pending.delete(id);
        resolve({ type: "error", code: "timeout", message: "no reply from the server",
                  fields: [] });
      }, REPLY_TIMEOUT_MS);
      this.pending.set(id, { resolve, timer });
      this.socket.send(JSON.stringify({ ...msg, id }));
    });
  }

  failPending(code) {
    for (const { resolve, timer } of this.pending.values()) {
      clearTimeout(timer);
      resolve({ type: "error", code, message: "connection closed", fields: [] });
    }
    this.pending.clear();
  }
}

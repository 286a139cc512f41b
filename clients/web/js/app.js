// The skyd web client: wires the connection to the live view, the world-state controls, the
// camera/exposure view, presets, statistics and the session's role.

import { ClockButtons } from "./clock_buttons.js";
import { Connection } from "./connection.js";
import { clearErrors, showError, showReplyError } from "./field_errors.js";
import { FrameView } from "./frame_view.js";
import { ObservationPanel } from "./observation_panel.js";
import { applyRole } from "./locks.js";
import { PanoramaView } from "./panorama_view.js";
import { Presets } from "./presets.js";
import { ProbePanel } from "./probe_panel.js";
import { SnapshotPanel } from "./snapshot_panel.js";
import { StatsPanel } from "./stats_panel.js";
import { TimeControls } from "./time_controls.js";
import { ViewControls } from "./view_controls.js";
import { WorldControls } from "./world_controls.js";
import { WorldSimView } from "./world_sim_view.js";
import { WeatherMapPanel } from "./weather_map_panel.js";

const $ = (id) => document.getElementById(id);
const show = (id, text) => { $(id).textContent = text; };
const TOKEN_KEY = "skyd-controller-token";
const RESUBSCRIBE_MS = 250;

const scheme = location.protocol === "https:" ? "wss:" : "ws:";
let subscription = null;    // the number of the subscription frames are drawn from
let frameSubscription = null; // the subscription the last `frame` message announced
let resubscribeTimer = null;
let stateRevision = 0;
// The world state as get_state gave it at connect, kept current by the values of every
// state_changed event and of the simulation events (the clock, the sun and moon, transitions)
// the hello asks for: no get_state after that.
let state = null;

const connection = new Connection(`${scheme}//${location.host}/`, {
  onStatus: (text) => show("connection", text),
  onOpen: () => start(),
  onMessage: (msg) => handleMessage(msg),
  onBinary: (buffer) => {
    if (frameSubscription === null || frameSubscription !== subscription) return;
    frames.draw(buffer).catch((e) => showError(null, `frame: ${e.message}`));
  },
});

const request = (msg) => connection.request(msg);
const sendSet = async (patch) => {
  const reply = await request({ type: "set", patch });
  if (reply.type === "ack") noteRevision(reply.revision);
  return reply;
};

const frames = new FrameView($("view"), (header, count, perSecond) => {
  show("frame-revision", String(header.revision));
  show("frame-count", String(count));
  show("fps", perSecond.toFixed(1));
  time.tick(header.simulationTime, header.revision);
});
const world = new WorldControls(document, sendSet);
const time = new TimeControls(sendSet);
const view = new ViewControls($("view"), () => scheduleResubscribe());
const presets = new Presets(request);
const stats = new StatsPanel();
const sim = new WorldSimView();
const clock = new ClockButtons(sendSet);
const probe = new ProbePanel($("view"), request, () => view.shown);
new PanoramaView($("panorama"), () => view.view(), () => view.shown);
new SnapshotPanel(() => view.view(), () => state && state.clock && state.clock.utc);
new WeatherMapPanel(request, noteRevision);
const observation = new ObservationPanel(request, noteRevision);

// Controls that need the controller role are disabled until an auth makes this session one.
function setRole(role) {
  show("role", role);
  applyRole(role);
}
setRole("viewer");

function noteRevision(revision) {
  if (typeof revision === "number" && revision >= stateRevision) {
    stateRevision = revision;
    show("revision", String(revision));
  }
}

function handleMessage(msg) {
  switch (msg.type) {
  case "hello":
    setRole(msg.role);
    break;
  case "frame":
    frameSubscription = msg.subscription === undefined ? null : msg.subscription;
    break;
  case "event":
    if (msg.event === "state_changed" || msg.event === "simulation") {
      noteRevision(msg.revision);
      applyEvent(msg);
    }
    break;
  case "error":
    showReplyError(msg, null);
    break;
  default:
    break;
  }
}

async function refreshState() {
  const reply = await request({ type: "get_state" });
  if (reply.type !== "state") return;
  noteRevision(reply.revision);
  state = reply.state;
  world.update(state);
  time.update(state);
  view.update(state);
  sim.update(state);
  clock.update(state);
  probe.update(state);
  observation.update(state);
}

// Writes a value at a JSON Pointer ("/sun/elevation_deg") of the local state.
function putAt(pointer, value) {
  const parts = pointer.split("/").slice(1).map((p) => p.replace(/~1/g, "/").replace(/~0/g, "~"));
  let node = state;
  for (const part of parts.slice(0, -1)) {
    if (node[part] === null || typeof node[part] !== "object") node[part] = {};
    node = node[part];
  }
  node[parts[parts.length - 1]] = value;
}

// An event's values (a client's state_changed, or the simulation's own once a second) go into
// the local state and on to the controls; the time and the simulation's view take the state
// only when the event changed them, so that a drag of the time slider is not undone between
// clock events.
function applyEvent(msg) {
  if (state === null || !msg.values) return; // the get_state at connect is on its way
  for (const [pointer, value] of Object.entries(msg.values)) putAt(pointer, value);
  const changed = Object.keys(msg.values);
  const touches = (...prefixes) => changed.some((p) => prefixes.some((q) => p.startsWith(q)));
  world.update(state);
  view.update(state);
  clock.update(state);
  probe.update(state);
  observation.update(state);
  if (touches("/clock/utc")) time.update(state);
  if (touches("/clock/", "/weather/transition/")) sim.update(state);
}

// Subscribes with the current view; the old subscription ends once the new one is running,
// so the image never goes blank.
async function resubscribe() {
  const reply = await request({ type: "subscribe", view: view.view() });
  if (reply.type !== "subscribed") {
    showReplyError(reply, "view:size");
    return;
  }
  clearErrors(["view:size", "view:camera.altitude_km", "view:camera.yaw_deg",
               "view:camera.pitch_deg", "view:camera.fov_deg", "view:exposure.mode",
               "view:exposure.ev100", "view:exposure.compensation_ev"]);
  const previous = subscription;
  subscription = reply.subscription;
  if (previous !== null) await request({ type: "unsubscribe", subscription: previous });
}

function scheduleResubscribe() {
  if (resubscribeTimer !== null) return;
  resubscribeTimer = setTimeout(() => { resubscribeTimer = null; resubscribe(); }, RESUBSCRIBE_MS);
}

async function authenticate(token) {
  const reply = await request({ type: "auth", token });
  if (reply.type === "ack") {
    setRole(reply.role);
    sessionStorage.setItem(TOKEN_KEY, token);
    clearErrors(["token"]);
  } else {
    sessionStorage.removeItem(TOKEN_KEY);
    showReplyError(reply, "token");
  }
}

// After every (re)connection: the role, the stream, the state and the preset lists.
async function start() {
  subscription = null;
  frameSubscription = null;
  state = null;
  await request({ type: "hello", client: "skyd-web 0.1", protocol: 1, simulation_events: true });
  const token = sessionStorage.getItem(TOKEN_KEY);
  if (token) await authenticate(token);
  await resubscribe();
  await refreshState();
  await presets.refresh();
}

// Query parameters preset the view: ?size=320x180&fps=10 (kiosk displays, tests).
const query = new URLSearchParams(location.search);
if (query.has("size") && [...$("view-size").options].some((o) => o.value === query.get("size")))
  $("view-size").value = query.get("size");
if (query.has("fps")) $("view-fps").value = query.get("fps");

$("auth").addEventListener("click", () => authenticate($("token").value));
$("token").addEventListener("keydown", (e) => {
  if (e.key === "Enter") authenticate($("token").value);
});

setInterval(async () => {
  if (!connection.open) return;
  const reply = await request({ type: "stats" });
  if (reply.type === "stats") {
    stats.update(reply);
    if (frames.count === 0) time.tick(reply.simulation_time_s, null);
  }
}, 1000);

// One frame from GET /api/snapshot (protocol/PROTOCOL.md, "HTTP API"): the view object
// flattened into query parameters. Its own request, so the live stream is left alone.

export function snapshotUrl(view) {
  const q = new URLSearchParams({ width: view.width, height: view.height });
  if (view.format) q.set("format", view.format);
  if (view.quality !== undefined) q.set("quality", view.quality);
  if (view.projection) q.set("projection", view.projection);
  for (const [key, value] of Object.entries(view.camera || {})) q.set(key, value);
  const e = view.exposure || {};
  if (e.mode) q.set("exposure_mode", e.mode);
  if (e.ev100 !== undefined) q.set("ev100", e.ev100);
  if (e.compensation_ev !== undefined) q.set("compensation_ev", e.compensation_ev);
  return `/api/snapshot?${q}`;
}

// Resolves with {blob} or with {error}, an `error` message as the WebSocket's replies carry
// (the HTTP API answers failures with the same JSON).
export async function fetchSnapshot(view) {
  let response;
  try {
    response = await fetch(snapshotUrl(view), { cache: "no-store" });
  } catch (e) {
    return { error: { type: "error", code: "disconnected", message: e.message, fields: [] } };
  }
  if (response.ok) return { blob: await response.blob() };
  let error;
  try {
    error = await response.json();
  } catch (e) {
    error = { type: "error", code: `http_${response.status}`, message: response.statusText,
              fields: [] };
  }
  return { error };
}

// Dragging and the wheel turn a camera: the live view and the panorama both look around this
// way. look() gives the camera now ({yaw_deg, pitch_deg, fov_deg}); turn(change) takes the new
// yaw and pitch after a drag, or the new field of view after a wheel step, within fovRange.

export const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, v));
export const wrapDegrees = (d) => ((d % 360) + 360) % 360;

export function bindLookDrag(canvas, look, turn, fovRange) {
  let last = null;
  canvas.addEventListener("pointerdown", (e) => {
    last = { x: e.clientX, y: e.clientY };
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener("pointermove", (e) => {
    if (!last) return;
    // Degrees per CSS pixel from the vertical field of view and the image's height on screen.
    const now = look();
    const perPixel = now.fov_deg / Math.max(1, canvas.clientHeight);
    const dx = e.clientX - last.x;
    const dy = e.clientY - last.y;
    last = { x: e.clientX, y: e.clientY };
    turn({ yaw_deg: wrapDegrees(now.yaw_deg - dx * perPixel),
           pitch_deg: clamp(now.pitch_deg + dy * perPixel, -90, 90) });
  });
  const end = () => { last = null; };
  canvas.addEventListener("pointerup", end);
  canvas.addEventListener("pointercancel", end);
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    turn({ fov_deg: clamp(look().fov_deg * Math.exp(e.deltaY * 0.001), fovRange[0], fovRange[1]) });
  }, { passive: false });
}

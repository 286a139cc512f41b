// A control may be disabled for more than one reason at once (the viewer role, the ephemeris
// placing the sun): each reason is kept in data-locks, so lifting one leaves the others.

export function setLock(element, reason, on) {
  const reasons = new Set((element.dataset.locks || "").split(" ").filter(Boolean));
  if (on) reasons.add(reason);
  else reasons.delete(reason);
  if (reasons.size) element.dataset.locks = [...reasons].join(" ");
  else delete element.dataset.locks;
  element.disabled = reasons.size > 0;
}

// Controls that send controller-only messages (set, apply_preset, set_weather_map): the
// world-state fields (data-path) and whatever is marked data-controller.
export function controllerControls(root = document) {
  return [...root.querySelectorAll("[data-path], [data-controller]")];
}

// Disables those controls unless the role is "controller".
export function applyRole(role, root = document) {
  const viewer = role !== "controller";
  for (const element of controllerControls(root)) setLock(element, "role", viewer);
  document.body.dataset.role = role;
}

// Server errors shown next to the control that caused them. An error entry's JSON Pointer
// ("/patch/location/latitude_deg", "/view/camera/fov_deg", "/kind") is mapped to the key of a
// `[data-error-for]` element: "location.latitude_deg", "view:camera.fov_deg"; what maps to no
// element goes to the fallback key of the control that sent the request.

const general = () => document.getElementById("error");

function slot(key) {
  return document.querySelector(`[data-error-for="${CSS.escape(key)}"]`);
}

// The error slot key for a pointer, or null. RGB channels ("/patch/atmosphere/ground_albedo/1")
// and deeper members fall back to the nearest field that has a slot.
export function keyForPointer(pointer) {
  const parts = pointer.split("/").slice(1).map((p) => p.replace(/~1/g, "/").replace(/~0/g, "~"));
  let prefix;
  if (parts[0] === "patch") prefix = "";
  else if (parts[0] === "view") prefix = "view:";
  else return null;
  if (prefix === "view:" && ["width", "height", "fps", "format"].includes(parts[1]))
    return slot("view:size") ? "view:size" : null;
  for (let n = parts.length; n > 1; n--) {
    const key = prefix + parts.slice(1, n).join(".");
    if (slot(key)) return key;
  }
  return null;
}

function describe(entry) {
  return `${entry.reason} (${entry.code})`;
}

function controlFor(element) {
  return element.closest(".field")?.querySelector("input, select");
}

export function clearError(key) {
  const element = slot(key);
  if (!element) return;
  element.textContent = "";
  const control = controlFor(element);
  if (control) control.removeAttribute("aria-invalid");
}

export function showError(key, text) {
  const element = key ? slot(key) : null;
  if (!element) {
    general().textContent = text;
    return;
  }
  element.textContent = text;
  const control = controlFor(element);
  if (control) control.setAttribute("aria-invalid", "true");
}

// Shows an `error` reply: each field entry next to its control, the rest next to the control
// the request came from (fallbackKey) or in the page's general error line.
export function showReplyError(reply, fallbackKey) {
  const fields = Array.isArray(reply.fields) ? reply.fields : [];
  let placed = false;
  for (const entry of fields) {
    const key = typeof entry.pointer === "string" ? keyForPointer(entry.pointer) : null;
    if (key) {
      showError(key, describe(entry));
      placed = true;
    }
  }
  if (!placed) showError(fallbackKey, `${reply.message || reply.code} (${reply.code})`);
}

// Clears the slots of keys after a successful request, and the general line.
export function clearErrors(keys) {
  for (const key of keys) clearError(key);
  general().textContent = "";
}

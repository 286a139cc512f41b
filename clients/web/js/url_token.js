// The address `skyd serve` prints, http://HOST:PORT/#token=TOKEN, opens the page as a
// controller: the token goes where a typed one is kept (sessionStorage, which app.js reads
// to authenticate after every connection) and leaves the address bar, so that it stays out
// of the history, bookmarks and screenshots. A fragment is never sent to the server.

const TOKEN_KEY = "skyd-controller-token"; // app.js keeps a typed token under the same key

// Returns whether a token was taken.
export function takeTokenFromFragment(loc = location, storage = sessionStorage, hist = history) {
  const fragment = new URLSearchParams(loc.hash.slice(1));
  if (!fragment.has("token")) return false;
  const token = fragment.get("token");
  fragment.delete("token");
  const rest = fragment.toString();
  hist.replaceState(hist.state, "", loc.pathname + loc.search + (rest ? `#${rest}` : ""));
  if (!token) return false;
  storage.setItem(TOKEN_KEY, token);
  return true;
}

takeTokenFromFragment();
// Such an address pasted into a tab already showing the page changes only the fragment: the
// page starts again to authenticate with the new token.
window.addEventListener("hashchange", () => {
  if (takeTokenFromFragment()) location.reload();
});

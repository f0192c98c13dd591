// A page's requests to its own server: the token the page was opened with (a page served
// beyond loopback is opened with ?token=...) travels on every request. Every page of the
// robot (the view, the buttons, the editor) asks through here.

const token = new URLSearchParams(location.search).get("token");

export function api(path, params = {}) {
  const query = new URLSearchParams(params);
  if (token) query.set("token", token);
  const text = query.toString();
  return text ? `${path}?${text}` : path;
}

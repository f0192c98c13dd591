// A page's requests to its own server. The browser's cookie carries the server's token
// (opening the address vest printed set it), so a request names only its path and query.
// Every page of the robot (the view, the buttons, the editor) asks through here.

export function api(path, params = {}) {
  const text = new URLSearchParams(params).toString();
  return text ? `${path}?${text}` : path;
}

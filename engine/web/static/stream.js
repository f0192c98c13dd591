// The one client for every live stream of vest's pages (the view, the buttons, the cloud's
// operator page): server-sent events read with fetch, which can send a token header
// (EventSource cannot), reconnecting with back-off when the connection is lost.

const FIRST_WAIT_MS = 500;
const LONGEST_WAIT_MS = 10000;

// Reads `url` and calls onEvent(name, data) for each event (name "message" when unnamed;
// data parsed from JSON) until onEvent returns false, `signal` aborts, or the server
// refuses (401/403). onState("open" | "lost" | "refused", status) says how the link is.
export async function follow(url, { headers = {}, onEvent, onState = () => {}, signal } = {}) {
  let waitMs = FIRST_WAIT_MS;
  for (;;) {
    try {
      const response = await fetch(url, {
        headers: { ...headers, Accept: "text/event-stream" },
        cache: "no-store",
        signal,
      });
      if (response.status === 401 || response.status === 403) {
        onState("refused", response.status);
        return;
      }
      if (response.ok) {
        onState("open", response.status);
        waitMs = FIRST_WAIT_MS;
        if ((await read(response, onEvent)) === "stopped") return;
      }
    } catch (error) {
      if (signal && signal.aborted) return;
    }
    if (signal && signal.aborted) return;
    onState("lost");
    await new Promise((resolve) => setTimeout(resolve, waitMs));
    waitMs = Math.min(waitMs * 2, LONGEST_WAIT_MS);
  }
}

async function read(response, onEvent) {
  const reader = response.body.pipeThrough(new TextDecoderStream()).getReader();
  let buffer = "";
  for (;;) {
    const { value, done } = await reader.read();
    if (done) return "ended";
    buffer += value;
    let end;
    while ((end = buffer.indexOf("\n\n")) >= 0) {
      const block = buffer.slice(0, end);
      buffer = buffer.slice(end + 2);
      let name = "message";
      const data = [];
      for (const line of block.split("\n")) {
        if (line.startsWith("event:")) name = line.slice(6).trim();
        else if (line.startsWith("data:")) data.push(line.slice(5).trimStart());
      }
      if (data.length && (await onEvent(name, JSON.parse(data.join("\n")))) === false) {
        await reader.cancel();
        return "stopped";
      }
    }
  }
}

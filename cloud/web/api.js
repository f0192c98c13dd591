// Talking to the service: JSON calls with the operator's bearer token, and the live
// stream of server-sent events (through the client every page of vest shares).

import { follow } from "/shared/stream.js";

export class ApiError extends Error {
  constructor(status, message) {
    super(message);
    this.status = status;
  }
}

function explain(status, body) {
  const detail = body && body.detail;
  if (Array.isArray(detail)) {
    return detail.map((d) => (d.field ? `${d.field}: ${d.message}` : d.message || JSON.stringify(d))).join("; ");
  }
  if (typeof detail === "string") return detail;
  return `the service answered ${status}`;
}

export class Api {
  constructor(token, base = "/api/v1") {
    this.token = token;
    this.base = base;
  }

  async call(method, path, body) {
    let response;
    try {
      response = await fetch(this.base + path, {
        method,
        headers: {
          Authorization: `Bearer ${this.token}`,
          ...(body === undefined ? {} : { "Content-Type": "application/json" }),
        },
        body: body === undefined ? undefined : JSON.stringify(body),
      });
    } catch (error) {
      throw new ApiError(0, "the service cannot be reached");
    }
    const text = await response.text();
    const data = text ? JSON.parse(text) : null;
    if (!response.ok) throw new ApiError(response.status, explain(response.status, data));
    return data;
  }

  // Follows the live stream: onEvent(name, data) for each event, reconnecting with back-off,
  // until `signal` aborts or the token is refused (onState("refused")).
  follow(onEvent, onState, signal) {
    const headers = { Authorization: `Bearer ${this.token}` };
    return follow(this.base + "/events", { headers, onEvent, onState, signal });
  }
}

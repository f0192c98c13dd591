// The operator's page: log in with your token, see the robots granted to you, their live
// session (and press their buttons, if your role may), their live sensor values (if your
// role may see them), send commands (if your role may) and follow each one to its end.

import { Api, ApiError } from "./api.js";
import { buildArgs, readCommand, typeOptions } from "./forms.js";
import { renderSession } from "./session.js";

const $ = (selector) => document.querySelector(selector);
const TOKEN_KEY = "vest-operator-token";
const FINISHED = new Set(["SUCCEEDED", "FAILED", "TIMED_OUT", "CANCELED"]);

const state = {
  api: null,
  me: null, // {name, role, can_command, can_press, sees_telemetry, expires_at_s}
  robots: [],
  selected: null,
  commands: new Map(), // robot -> Map(id -> command)
  telemetry: new Map(), // robot -> {key: {value, at_s}}
  catalogues: new Map(), // robot -> {type: [params]}
  sessions: new Map(), // robot -> {view, at_s}: its live session as it last sent it
  presses: new Map(), // robot -> {label, command}: this page's last press
  stream: null,
};

function el(tag, props = {}, ...children) {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children);
  return node;
}

const shown = (value) => (typeof value === "string" ? value : JSON.stringify(value));
const clock = (seconds) => new Date(seconds * 1000).toLocaleTimeString();

function ago(seconds) {
  if (seconds === null || seconds === undefined) return "never";
  const s = Math.max(0, Date.now() / 1000 - seconds);
  if (s < 60) return `${Math.round(s)} s ago`;
  if (s < 3600) return `${Math.round(s / 60)} min ago`;
  return new Date(seconds * 1000).toLocaleString();
}

// -- logging in and out --------------------------------------------------------------------

async function login(token) {
  const api = new Api(token);
  try {
    state.me = await api.call("GET", "/me");
    state.robots = await api.call("GET", "/robots");
  } catch (error) {
    sessionStorage.removeItem(TOKEN_KEY);
    const expired = error.message.includes("expired");
    $("#login-error").textContent =
      error.status === 401 && !expired ? "That token is not valid (or it was revoked)." : error.message;
    return;
  }
  sessionStorage.setItem(TOKEN_KEY, token);
  state.api = api;
  $("#login").hidden = true;
  $("#console").hidden = false;
  $("#logout").hidden = false;
  $("#login-error").textContent = "";
  showRole(state.me);
  renderRobots();
  if (state.robots.length) await select(state.robots[0].name);
  follow();
}

function logout() {
  sessionStorage.removeItem(TOKEN_KEY);
  if (state.stream) state.stream.abort();
  location.reload();
}

// What the role lets this person do: a role that may not command sees commands read-only,
// one that may not see telemetry (a viewer) sees a sentence instead of sensor values.
function showRole(me) {
  $("#who").hidden = false;
  $("#who").textContent = `${me.name} (${me.role})`;
  for (const node of document.querySelectorAll(".role")) node.textContent = me.role;
  $("#send").hidden = !me.can_command;
  $("#read-only").hidden = me.can_command;
  $("#sensors").hidden = !me.sees_telemetry;
  $("#sensors-hidden").hidden = me.sees_telemetry;
}

// -- the live stream -------------------------------------------------------------------------

function follow() {
  state.stream = new AbortController();
  const onState = (link) => {
    if (link === "refused") logout();
    else setLink(link === "open");
  };
  state.api.follow(onEvent, onState, state.stream.signal);
}

function setLink(up) {
  $("#link").hidden = up;
  $("#link").textContent = up ? "" : "reconnecting…";
}

function onEvent(name, data) {
  if (name === "robots") {
    state.robots = data;
    renderRobots();
    showSession();
  } else if (name === "command") {
    if (!state.commands.has(data.robot)) state.commands.set(data.robot, new Map());
    const known = state.commands.get(data.robot).get(data.id);
    if (!known || known.version <= data.version) state.commands.get(data.robot).set(data.id, data);
    const press = state.presses.get(data.robot);
    if (press && press.command.id === data.id) press.command = data;
    if (data.robot === state.selected) {
      renderCommands();
      if (press) showSession();
    }
  } else if (name === "session") {
    state.sessions.set(data.robot, data);
    if (data.robot === state.selected) showSession();
  } else if (name === "telemetry") {
    state.telemetry.set(data.robot, { ...(state.telemetry.get(data.robot) || {}), ...data.values });
    if (data.robot === state.selected) renderTelemetry();
  }
}

// -- robots ----------------------------------------------------------------------------------

function renderRobots() {
  $("#no-robots").hidden = state.robots.length > 0;
  $("#robots").replaceChildren(
    ...state.robots.map((robot) => {
      const button = el(
        "button",
        { type: "button", className: robot.online ? "online" : "offline" },
        el("span", {}, el("span", { className: "dot" }), robot.name),
        el("span", { className: "seen", textContent: robot.online ? "online" : `offline, seen ${ago(robot.last_seen_s)}` }),
      );
      button.dataset.robot = robot.name;
      button.setAttribute("aria-current", String(robot.name === state.selected));
      button.addEventListener("click", () => select(robot.name));
      return el("li", {}, button);
    }),
  );
  renderStatus();
}

function renderStatus() {
  const robot = state.robots.find((r) => r.name === state.selected);
  if (!robot) return;
  $("#robot-status").textContent = robot.online
    ? "Online"
    : `Offline: last seen ${ago(robot.last_seen_s)}. Commands wait for it (until they time out); presses are dropped.`;
}

async function select(name) {
  if (!state.catalogues.has(name)) {
    try {
      state.catalogues.set(name, await state.api.call("GET", `/robots/${encodeURIComponent(name)}/command-types`));
    } catch (error) {
      $("#send-error").textContent = error.message;
      return;
    }
  }
  const catalogue = state.catalogues.get(name);
  const chosen = $("#type").value;
  state.selected = name;
  $("#robot").hidden = false;
  $("#robot").dataset.robot = name;
  $("#robot-name").textContent = name;
  $("#send-error").textContent = "";
  typeOptions($("#type"), catalogue);
  if (chosen && [...$("#type").options].some((option) => option.value === chosen)) $("#type").value = chosen;
  buildArgs($("#args"), $("#type").value, catalogue);
  renderRobots();
  renderCommands();
  renderTelemetry();
  showSession();
}

// -- the live session and its buttons --------------------------------------------------------

function showSession() {
  const robot = state.robots.find((r) => r.name === state.selected);
  renderSession($("#session"), state.sessions.get(state.selected), {
    canPress: state.me.can_press,
    online: Boolean(robot && robot.online),
    role: state.me.role,
    onPress: press,
    lastPress: state.presses.get(state.selected),
  });
}

async function press(button) {
  const robot = state.selected;
  $("#press-error").textContent = "";
  state.presses.set(robot, { label: button.label, command: { id: null, state: "QUEUED" } });
  showSession();
  try {
    const command = await state.api.call("POST", `/robots/${encodeURIComponent(robot)}/press`, {
      button: button.id,
    });
    const known = state.commands.get(robot) && state.commands.get(robot).get(command.id);
    state.presses.set(robot, { label: button.label, command: known && known.version > command.version ? known : command });
    showSession();
  } catch (error) {
    state.presses.delete(robot);
    showSession();
    $("#press-error").textContent = error.message;
  }
}

// -- commands --------------------------------------------------------------------------------

function idempotencyKey() {
  const bytes = crypto.getRandomValues(new Uint8Array(16));
  return Array.from(bytes, (b) => b.toString(16).padStart(2, "0")).join("");
}

async function send(event) {
  event.preventDefault();
  const robot = state.selected;
  const catalogue = state.catalogues.get(robot);
  $("#send-error").textContent = "";
  let command;
  try {
    command = readCommand($("#args"), $("#type").value, catalogue);
  } catch (error) {
    $("#send-error").textContent = error.message;
    return;
  }
  const button = $("#send button[type=submit]");
  button.disabled = true;
  try {
    const sent = await state.api.call("POST", `/robots/${encodeURIComponent(robot)}/commands`, {
      ...command,
      idempotency_key: idempotencyKey(),
    });
    onEvent("command", sent);
  } catch (error) {
    $("#send-error").textContent = error.message;
  } finally {
    button.disabled = false;
  }
}

async function cancel(command) {
  try {
    onEvent("command", await state.api.call("POST", `/robots/${encodeURIComponent(command.robot)}/commands/${command.id}/cancel`));
  } catch (error) {
    $("#send-error").textContent = error.message;
  }
}

// A command's arguments as the page shows them: a press names its button and who pressed.
function described(command) {
  if (command.type !== "press") return el("code", { textContent: shown(command.args) });
  const session = state.sessions.get(command.robot);
  const board = session && session.view.board;
  const button = board && board.buttons.find((b) => b.id === command.args.button);
  const name = button ? `'${button.label}'` : `button ${command.args.button}`;
  return `${name} by ${command.args.by}`;
}

function renderCommands() {
  const commands = [...(state.commands.get(state.selected) || new Map()).values()].sort(
    (a, b) => b.created_s - a.created_s,
  );
  $("#no-commands").hidden = commands.length > 0;
  $("#commands tbody").replaceChildren(
    ...commands.map((c) => {
      const row = el(
        "tr",
        {},
        el("td", { textContent: clock(c.created_s) }),
        el("td", {}, el("strong", { textContent: c.type }), " ", described(c)),
        el("td", {}, el("span", { className: `state ${c.state}`, textContent: c.state })),
        el("td", {}, el("pre", {
          textContent: c.result_hidden ? "(not shown to a viewer)"
            : c.result === null || c.result === undefined ? "" : shown(c.result),
        })),
        el("td"),
      );
      row.dataset.command = c.id;
      row.dataset.state = c.state;
      if (!FINISHED.has(c.state) && state.me.can_command) {
        const button = el("button", { type: "button", className: "cancel", textContent: "Cancel" });
        button.addEventListener("click", () => cancel(c));
        row.lastChild.append(button);
      }
      return row;
    }),
  );
}

// -- telemetry -------------------------------------------------------------------------------

const DEVICE = /^\/devices\/(.+)\/ok$/;

function renderTelemetry() {
  const values = state.telemetry.get(state.selected) || {};
  const keys = Object.keys(values).sort();
  const devices = keys.filter((key) => DEVICE.test(key));
  const sensors = keys.filter((key) => !DEVICE.test(key));
  $("#devices").replaceChildren(
    ...devices.map((key) => {
      const ok = values[key].value === true;
      const item = el("li", { className: ok ? "online" : "offline", textContent: `${key.match(DEVICE)[1]}: ${ok ? "ok" : "offline"}` });
      item.dataset.key = key;
      return item;
    }),
  );
  $("#no-telemetry").hidden = keys.length > 0;
  $("#telemetry tbody").replaceChildren(
    ...sensors.map((key) => {
      const row = el(
        "tr",
        {},
        el("td", {}, el("code", { textContent: key })),
        el("td", {}, el("code", { textContent: shown(values[key].value) })),
        el("td", { className: "age", textContent: ago(values[key].at_s) }),
      );
      row.dataset.key = key;
      return row;
    }),
  );
}

// -- wiring ----------------------------------------------------------------------------------

$("#login").addEventListener("submit", (event) => {
  event.preventDefault();
  login($("#token").value.trim());
});
$("#login button[type=submit]").disabled = false; // wired: logging in stays in the page
$("#logout").addEventListener("click", logout);
$("#send").addEventListener("submit", send);
$("#type").addEventListener("change", () => {
  $("#send-error").textContent = "";
  buildArgs($("#args"), $("#type").value, state.catalogues.get(state.selected));
});
setInterval(() => {
  if (state.selected) {
    renderTelemetry();
    renderStatus();
  }
}, 1000);

const saved = sessionStorage.getItem(TOKEN_KEY);
if (saved) login(saved);

// The therapist's buttons: each press goes to the robot, which carries it out within a
// tick; which buttons show follows what the robot is doing (server-sent events).

import { follow } from "/shared/stream.js";
import { api } from "/shared/address.js";

const $ = (selector) => document.querySelector(selector);
const byKey = new Map(); // keyboard key -> button id
const elements = new Map(); // button id -> <button>
let ended = false;

function keyName(event) {
  if (event.key === " ") return "Space";
  return event.key.length === 1 ? event.key.toLowerCase() : event.key;
}

async function press(id) {
  const element = elements.get(id);
  if (ended || !element || element.hidden) return;
  const response = await fetch(api("/api/press"), {
    method: "POST",
    headers: { "Content-Type": "application/json" },
    body: JSON.stringify({ button: id }),
  });
  if (response.ok) {
    element.classList.add("pressed");
    setTimeout(() => element.classList.remove("pressed"), 400);
  } else {
    $("#state").textContent = `the robot refused: ${await response.text()}`;
  }
}

function show(state) {
  if (state.ended) {
    ended = true;
    $("#state").textContent = "the session ended";
    $("#state").className = "ended";
    for (const element of elements.values()) element.disabled = true;
    for (const element of document.querySelectorAll("#vest button")) element.disabled = true;
    return;
  }
  const shown = new Set(state.shown);
  for (const [id, element] of elements) {
    element.hidden = !shown.has(id);
    element.classList.toggle("doing", element.dataset.label === state.doing);
  }
  const what = state.doing ? `doing "${state.doing}"` : "ready";
  $("#state").textContent = state.paused ? `behaviors paused; ${what}` : what;
  $("#state").className = state.paused ? "paused" : "";
}

// On a simulated vest: a squeeze, a touch or a child's words, acted now (POST /api/act
// takes one scenario event; the robot feels it at its next tick).
async function act(event) {
  const response = await fetch(api("/api/act"), {
    method: "POST",
    headers: { "Content-Type": "application/json" },
    body: JSON.stringify(event),
  });
  const told = $("#acted");
  if (response.ok) {
    told.textContent = `done: ${(await response.json()).acted}`;
    told.className = "";
  } else {
    told.textContent = `not done: ${await response.text()}`;
    told.className = "refused";
  }
}

function actsOn(board) {
  if (!board.acts || ended) return;
  $("#vest").hidden = false;
  const pads = $("#act-touch select");
  const names = board.pads.length ? board.pads : [...Array(12).keys()].map(String);
  names.forEach((name, index) => {
    const option = document.createElement("option");
    option.value = board.pads.length ? name : String(index);
    option.textContent = board.pads.length ? name.replaceAll("_", " ") : `pad ${index}`;
    pads.append(option);
  });
  const submitted = (id, build) =>
    $(id).addEventListener("submit", (event) => {
      event.preventDefault();
      if (!ended) act(build(new FormData(event.target)));
    });
  submitted("#act-squeeze", (form) => {
    const newtons = Number(form.get("newtons"));
    const side = form.get("side");
    return {
      squeeze: {
        left_n: side === "right" ? 0 : newtons,
        right_n: side === "left" ? 0 : newtons,
        seconds: Number(form.get("seconds")),
      },
    };
  });
  submitted("#act-touch", (form) => {
    const pad = form.get("pad");
    return { touch: { pad: board.pads.length ? pad : Number(pad), seconds: Number(form.get("seconds")) } };
  });
  submitted("#act-hear", (form) => ({ hear: { text: String(form.get("text")) } }));
}

// what the robot and the world did lately, newest first, so the therapist sees the robot's
// answers without its terminal (the live view's words, from the same stream)
const SHOWN_HAPPENINGS = 8;
let happenings = [];

function drawHappenings() {
  $("#happened").replaceChildren(...happenings.slice(-SHOWN_HAPPENINGS).reverse().map((entry) => {
    const item = document.createElement("li");
    item.textContent = `${entry.at.toFixed(1)} s ${entry.who}: ${entry.what}`; // text, never markup
    return item;
  }));
}

async function watchHappenings() {
  const snapshot = async () => {
    const response = await fetch(api("/api/snapshot"));
    if (response.ok) happenings = (await response.json()).happened ?? [];
    drawHappenings();
  };
  const onEvent = async (name, change) => {
    if (change.kind === "end") return false;
    if (change.kind === "resync") await snapshot();
    if (change.kind === "happened") {
      happenings = [...happenings, change].slice(-50);
      drawHappenings();
    }
    return !ended;
  };
  follow(api("/api/events"), { onEvent, onState: () => {} });
}

async function start() {
  const response = await fetch(api("/api/buttons"));
  if (!response.ok) {
    $("#state").textContent = `no buttons here (${response.status})`;
    return;
  }
  const board = await response.json();
  const container = $("#buttons");
  for (const button of board.buttons) {
    const element = document.createElement("button");
    element.type = "button";
    element.dataset.label = button.label;
    element.textContent = button.label; // text, never markup
    if (button.key) {
      const key = document.createElement("span");
      key.className = "key";
      key.textContent = button.key;
      element.append(key);
      byKey.set(button.key, button.id);
    }
    if (button.control) element.classList.add(`control-${button.control}`);
    element.addEventListener("click", () => press(button.id));
    elements.set(button.id, element);
    container.append(element);
  }
  $("#trees-link").href = api("/");
  show(board.state);
  actsOn(board);
  watchHappenings();
  const onEvent = (name, state) => {
    show(state);
    return !ended;
  };
  const onState = (link) => {
    if (!ended && link !== "open") $("#state").textContent = "connection lost: retrying...";
  };
  follow(api("/api/buttons/events"), { onEvent, onState });
}

document.addEventListener("keydown", (event) => {
  if (event.ctrlKey || event.metaKey || event.altKey || event.repeat) return;
  if (event.target.closest("input, select, textarea")) return; // typing, not pressing
  const id = byKey.get(keyName(event));
  if (id !== undefined) {
    event.preventDefault();
    press(id);
  }
});

start();

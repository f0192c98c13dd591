// The view of the robot's trees: live (server-sent changes) or a replay (a slider over a
// recording). One data model for both: the server's snapshot, then changes applied to it.

import { follow } from "/shared/stream.js";
import { cleanSvg } from "/shared/drawing.js";
import { api } from "/shared/address.js";

const $ = (selector) => document.querySelector(selector);

const state = { trees: new Map(), keys: new Map(), happened: [], stats: null, now: 0 };
const history = new Map(); // "tree/version/node" -> [{at, status, feedback}], live only
let info = { mode: "live" };
let chosen = null; // {tree, version, node}
const MAX_HISTORY = 20;
const WORDS = { RUNNING: "running", SUCCESS: "succeeded", FAILURE: "did not succeed", INVALID: "stopped" };
const ANSWERS = { SUCCESS: "answered yes", FAILURE: "answered no", INVALID: "stopped" }; // a question

function nodeKey(tree, version, node) {
  return `${tree}/${version}/${node}`;
}

async function getJson(path, params) {
  const response = await fetch(api(path, params));
  if (!response.ok) throw new Error(`${path}: ${response.status}`);
  return response.json();
}

function load(snapshot) {
  state.now = snapshot.now;
  state.trees = new Map(snapshot.trees.map((tree) => [tree.tree, tree]));
  for (const tree of state.trees.values()) {
    tree.byNode = new Map(tree.statuses.map((change) => [change.node, change]));
  }
  state.keys = new Map(snapshot.keys.map((change) => [change.key, change]));
  state.happened = snapshot.happened ?? [];
  state.stats = snapshot.stats;
}

// -- what a status means to a reader ------------------------------------------------------
// A question (a condition, drawn as an ellipse) that answers no has not failed: the robot
// is waiting for something. A node that failed only because its questions said no is
// waiting too; it failed when something it did failed. Each status has a word and a mark
// as well as a colour (the legend in index.html shows them once for every drawing).
const SHOWN = {
  running: { mark: "\u25B6", word: "running" },
  done: { mark: "\u2713", word: "done" },
  yes: { mark: "\u2713", word: "yes" },
  failed: { mark: "\u2717", word: "failed" },
  no: { mark: "\u2013", word: "no" },
  waiting: { mark: "\u2026", word: "waiting" },
  idle: { mark: "", word: "not run yet" },
};

const questions = new Map(); // "tree/version" -> the numbers of its conditions (ellipses)

function parents(tree) {
  const stack = [];
  return tree.nodes.map((node) => {
    stack.length = node.depth;
    const parent = node.depth > 0 ? stack[node.depth - 1] : null;
    stack[node.depth] = node.index;
    return parent;
  });
}

function shownStatuses(tree) {
  const parent = parents(tree);
  const shown = new Array(tree.nodes.length).fill("idle");
  const failedBelow = new Array(tree.nodes.length).fill(false);
  for (let index = tree.nodes.length - 1; index >= 0; index -= 1) { // children first
    const change = tree.byNode.get(index);
    const status = change ? change.status : "INVALID";
    const question = Boolean(questions.get(`${tree.tree}/${tree.version}`)?.has(index));
    if (status === "RUNNING") shown[index] = "running";
    else if (status === "SUCCESS") shown[index] = question ? "yes" : "done";
    else if (status === "FAILURE") {
      const leaf = !tree.nodes.some((_, child) => parent[child] === index);
      if (question) shown[index] = "no";
      else shown[index] = leaf || failedBelow[index] ? "failed" : "waiting";
    }
    if (shown[index] === "failed" && parent[index] !== null) failedBelow[parent[index]] = true;
  }
  return shown;
}

// -- drawing ------------------------------------------------------------------------------
async function drawTrees() {
  const container = $("#trees");
  const wanted = [...state.trees.values()];
  const present = new Set(wanted.map((tree) => `${tree.tree}/${tree.version}`));
  for (const card of [...container.children]) {
    if (!present.has(card.dataset.id)) card.remove();
  }
  for (const tree of wanted) {
    const id = `${tree.tree}/${tree.version}`;
    if (container.querySelector(`[data-id="${CSS.escape(id)}"]`)) continue;
    const card = document.createElement("article");
    card.className = "tree";
    card.dataset.id = id;
    card.dataset.tree = tree.tree;
    card.innerHTML = `<h2><span class="name"></span> <span class="status"></span>
      <button type="button" class="fit" aria-pressed="false">fit to width</button></h2>
      <div class="drawing" tabindex="0" role="group">drawing...</div>`;
    card.querySelector("h2 .name").textContent = `${tree.tree} (${tree.rate_hz} times a second)`;
    const drawing = card.querySelector(".drawing");
    drawing.setAttribute("aria-label", `the ${tree.tree} tree`);
    const fit = card.querySelector(".fit");
    fit.addEventListener("click", () => {
      const fitted = card.classList.toggle("fitted");
      fit.setAttribute("aria-pressed", String(fitted));
    });
    container.append(card);
    const response = await fetch(api(`/api/svg/${encodeURIComponent(tree.tree)}/${tree.version}`));
    if (response.ok) {
      drawing.replaceChildren(cleanSvg(await response.text()));
      const svg = drawing.querySelector("svg");
      if (svg) {
        // every tree at one scale (a big tree scrolls in its card, its words stay readable)
        const width = svg.width.baseVal.valueInSpecifiedUnits;
        const height = svg.height.baseVal.valueInSpecifiedUnits;
        svg.style.width = `${Math.round(width * 0.9)}px`;
        svg.style.height = `${Math.round(height * 0.9)}px`;
      }
      const asks = new Set();
      questions.set(id, asks);
      for (const group of drawing.querySelectorAll("g.node")) {
        const title = group.querySelector("title")?.textContent ?? "";
        if (!/^n\d+$/.test(title)) continue;
        const index = Number(title.slice(1));
        group.dataset.node = String(index);
        if (group.querySelector("ellipse")) asks.add(index); // a condition's shape
        chooseBy(group, tree, index);
        const shape = group.querySelector("polygon, ellipse");
        const box = shape ? shape.getBBox() : null;
        if (box) { // the status's mark, at the shape's top right corner
          const mark = document.createElementNS("http://www.w3.org/2000/svg", "text");
          mark.setAttribute("class", "mark");
          mark.setAttribute("x", String(box.x + box.width - 3));
          mark.setAttribute("y", String(box.y + 12));
          mark.setAttribute("text-anchor", "end");
          mark.setAttribute("aria-hidden", "true");
          group.append(mark);
        }
      }
    } else {
      // no Graphviz on this machine: the nodes as an indented list
      const list = document.createElement("ul");
      for (const node of tree.nodes) {
        const item = document.createElement("li");
        item.dataset.node = String(node.index);
        item.style.marginLeft = `${node.depth * 1.2}em`;
        item.innerHTML = `<span class="mark" aria-hidden="true"></span> <span class="label"></span>`;
        item.querySelector(".label").textContent = node.words || node.label;
        chooseBy(item, tree, node.index);
        list.append(item);
      }
      drawing.replaceChildren(list);
    }
    colorTree(tree);
  }
}

function colorTree(tree) {
  const card = document.querySelector(`.tree[data-id="${CSS.escape(`${tree.tree}/${tree.version}`)}"]`);
  if (!card) return;
  const shown = shownStatuses(tree);
  for (const element of card.querySelectorAll("[data-node]")) {
    const index = Number(element.dataset.node);
    const change = tree.byNode.get(index);
    const { mark, word } = SHOWN[shown[index]];
    for (const name of Object.keys(SHOWN)) element.classList.remove(`st-${name}`);
    element.classList.add(`st-${shown[index]}`);
    element.dataset.status = change ? change.status : "INVALID";
    element.dataset.shown = shown[index];
    const markElement = element.querySelector(".mark");
    if (markElement) markElement.textContent = mark;
    element.setAttribute("aria-label", `${tree.nodes[index]?.words || tree.nodes[index]?.label || ""}: ${word}`);
    const isChosen = chosen && chosen.tree === tree.tree && chosen.version === tree.version
      && chosen.node === index;
    element.classList.toggle("chosen", Boolean(isChosen));
  }
  const status = card.querySelector("h2 .status");
  status.textContent = SHOWN[shown[0] ?? "idle"].word;
  status.className = `status st-${shown[0] ?? "idle"}`;
}

// a node is chosen by a click, or from the keyboard (Tab to it, then Enter or Space)
function chooseBy(element, tree, index) {
  element.setAttribute("tabindex", "0");
  element.setAttribute("role", "button");
  element.addEventListener("click", () => choose(tree.tree, tree.version, index));
  element.addEventListener("keydown", (event) => {
    if (event.key !== "Enter" && event.key !== " ") return;
    event.preventDefault();
    choose(tree.tree, tree.version, index);
  });
}

// a blackboard value as a person reads it: words unquoted, nothing for null, lists joined
function readable(json) {
  let value;
  try { value = JSON.parse(json); } catch { return String(json); }
  if (value === null) return "nothing";
  if (value === true) return "yes";
  if (value === false) return "no";
  if (Array.isArray(value)) {
    if (value.length === 0) return "none";
    if (value.every((each) => typeof each === "boolean")) {
      const on = value.flatMap((each, at) => (each ? [String(at)] : []));
      return on.length ? `on: ${on.join(", ")} (of ${value.length})` : `all ${value.length} off`;
    }
    return value.map((each) => (typeof each === "object" ? JSON.stringify(each) : String(each))).join(", ");
  }
  return typeof value === "object" ? JSON.stringify(value) : String(value);
}

function fill(selector, rows) {
  const body = $(`${selector} tbody`);
  body.replaceChildren(...rows.map(([cells, fresh, testId]) => {
    const row = document.createElement("tr");
    if (fresh) row.className = "fresh";
    if (testId) row.dataset.key = testId;
    for (const [text, className] of cells) {
      const cell = document.createElement("td");
      cell.textContent = text;
      if (className) cell.className = className;
      row.append(cell);
    }
    return row;
  }));
}

// where the camera sees a hand held up: the frame's outline and the hand's box (the
// picture itself is never sent: only where the hand is, and its count)
function drawCamera() {
  const svg = $("#camera-frame");
  const boxed = state.keys.get("/vision/hand/box");
  const fingers = state.keys.get("/vision/hand/fingers");
  let box = null;
  try { box = boxed ? JSON.parse(boxed.value) : null; } catch { box = null; }
  const ns = "http://www.w3.org/2000/svg";
  const frame = document.createElementNS(ns, "rect");
  const width = box ? box.frame_width : 640;
  const height = box ? box.frame_height : 480;
  svg.setAttribute("viewBox", `0 0 ${width} ${height}`);
  for (const [name, value] of Object.entries({ x: 1, y: 1, width: width - 2, height: height - 2, class: "frame" })) {
    frame.setAttribute(name, value);
  }
  const parts = [frame];
  let said = "no hand held up";
  if (box) {
    const hand = document.createElementNS(ns, "rect");
    for (const [name, value] of Object.entries({ x: box.x, y: box.y, width: box.width, height: box.height, class: "hand" })) {
      hand.setAttribute(name, value);
    }
    parts.push(hand);
    let count = null;
    try { count = fingers ? JSON.parse(fingers.value) : null; } catch { count = null; }
    const shown = count === null ? "its count not sure" : `${count} finger${count === 1 ? "" : "s"}`;
    said = `a hand held up at ${box.x},${box.y} (${box.width}x${box.height} px of ${width}x${height}): ${shown}`;
  }
  svg.replaceChildren(...parts);
  $("#camera-said").textContent = said;
}

function drawTables() {
  drawCamera();
  $("#clock").textContent = `${state.now.toFixed(2)} s`;
  const keys = [...state.keys.values()].sort((a, b) => a.key.localeCompare(b.key));
  fill("#keys", keys.map((change) => [[
    [change.key], [readable(change.value), "value"], [change.at.toFixed(2)], [change.writer || ""],
  ], state.now - change.at < 1, change.key]));
  const online = new Map();
  for (const change of keys) {
    const match = /^\/devices\/(.+)\/ok$/.exec(change.key);
    if (match) online.set(match[1], change.value === "true");
  }
  const devices = state.stats ? state.stats.devices : {};
  const names = [...new Set([...online.keys(), ...Object.keys(devices)])].sort();
  fill("#devices", names.map((name) => {
    const stats = devices[name];
    const isOnline = stats ? stats.online : online.get(name);
    return [[
      [name], [isOnline === false ? "offline" : "online"],
      [stats ? String(stats.transactions) : "-"], [stats ? String(stats.retries) : "-"],
      [stats ? String(stats.errors) : "-"], [stats ? String(Math.round(stats.latency_p99_us ?? 0)) : "-"],
    ], isOnline === false, name];
  }));
  const ticks = state.stats ? Object.entries(state.stats.trees) : [];
  fill("#ticks", ticks.length || info.mode !== "replay" ? ticks.map(([name, stats]) => [[
    [name], [String(stats.ticks)], [stats.duration_p99_ms.toFixed(3)],
    [stats.lateness_p99_ms.toFixed(2)], [String(stats.skipped)],
  ], false, name]) : [[[["(tick statistics are not in recordings)"]], false, ""]]);
  const list = $("#actions");
  const recent = state.happened.slice(-40);
  // each line says who did what in words; its kind is written out too, never colour alone
  list.replaceChildren(...recent.reverse().map((entry) => {
    const item = document.createElement("li");
    item.className = `tone-${entry.tone}`;
    item.dataset.tone = entry.tone;
    item.textContent = `${entry.at.toFixed(2)} s ${entry.who}: ${entry.what}`;
    return item;
  }));
}

async function draw() {
  await drawTrees();
  for (const tree of state.trees.values()) colorTree(tree);
  drawTables();
  showChosen();
}

// -- a chosen node ------------------------------------------------------------------------
function choose(tree, version, node) {
  chosen = { tree, version, node };
  $("#next-change").disabled = info.mode !== "replay";
  for (const each of state.trees.values()) colorTree(each);
  showChosen();
}

async function showChosen() {
  const panel = $("#node");
  if (!chosen) return;
  const tree = state.trees.get(chosen.tree);
  if (!tree || tree.version !== chosen.version) { panel.hidden = true; return; }
  panel.hidden = false;
  const node = tree.nodes[chosen.node];
  const change = tree.byNode.get(chosen.node);
  const facts = [
    ["tree", `${tree.tree} (version ${tree.version})`], ["node", `n${node.index}`],
    ["path", node.path], ["type", node.type], ["parameters", node.label],
    ["now", SHOWN[shownStatuses(tree)[chosen.node]].word],
    ["since", change ? `${change.at.toFixed(2)} s` : "-"],
    ["feedback", change && change.feedback ? change.feedback : "-"],
  ];
  $("#node-facts").replaceChildren(...facts.flatMap(([name, value]) => {
    const term = document.createElement("dt");
    term.textContent = name;
    const detail = document.createElement("dd");
    detail.textContent = value;
    return [term, detail];
  }));
  let changes = history.get(nodeKey(tree.tree, tree.version, node.index)) ?? [];
  if (info.mode === "replay") {
    const all = await getJson("/api/node", { tree: tree.tree, version: tree.version, node: node.index });
    changes = all.filter((each) => each.at <= state.now).slice(-MAX_HISTORY);
  }
  const asked = Boolean(questions.get(`${tree.tree}/${tree.version}`)?.has(node.index));
  $("#node-changes").replaceChildren(...changes.slice().reverse().map((each) => {
    const item = document.createElement("li");
    const said = asked ? ANSWERS[each.status] : WORDS[each.status];
    item.textContent = `${each.at.toFixed(2)} s ${said ?? each.status}${each.feedback ? `: ${each.feedback}` : ""}`;
    return item;
  }));
}

// -- live ---------------------------------------------------------------------------------
function apply(change) {
  if (change.at !== undefined) state.now = Math.max(state.now, change.at);
  if (change.kind === "status") {
    const tree = state.trees.get(change.tree);
    if (!tree || tree.version !== change.version) return;
    tree.byNode.set(change.node, change);
    const key = nodeKey(change.tree, change.version, change.node);
    const list = history.get(key) ?? [];
    list.push(change);
    if (list.length > MAX_HISTORY) list.shift();
    history.set(key, list);
    dirtyTrees.add(tree);
  } else if (change.kind === "key") {
    state.keys.set(change.key, change);
  } else if (change.kind === "happened") {
    state.happened.push(change);
    if (state.happened.length > 100) state.happened.shift();
  } else if (change.kind === "stats") {
    state.stats = change;
  }
}

const dirtyTrees = new Set();
let scheduled = false;
function redrawSoon() {
  if (scheduled) return;
  scheduled = true;
  requestAnimationFrame(() => {
    scheduled = false;
    for (const tree of dirtyTrees) colorTree(tree);
    dirtyTrees.clear();
    drawTables();
    showChosen();
  });
}

async function live() {
  $("#mode").textContent = "live";
  load(await getJson("/api/snapshot"));
  await draw();
  const onEvent = async (name, change) => {
    if (change.kind === "end") {
      state.now = change.at;
      drawTables();
      $("#mode").textContent = `session ended at ${change.at.toFixed(2)} s`;
      document.body.dataset.ended = "true";
      return false;
    }
    if (change.kind === "resync" || change.kind === "tree") {
      load(await getJson("/api/snapshot"));
      await draw();
      return true;
    }
    apply(change);
    redrawSoon();
    return true;
  };
  const onState = (link) => {
    if (document.body.dataset.ended === "true") return;
    $("#mode").textContent = link === "open" ? "live" : "live (connection lost: retrying)";
  };
  follow(api("/api/events"), { onEvent, onState });
}

// -- replay -------------------------------------------------------------------------------
let playing = null;
async function showMoment(at) {
  const moment = Math.max(0, Math.min(info.duration, at));
  load(await getJson("/api/snapshot", { at: String(moment) }));
  state.now = moment;
  $("#slider").value = String(moment);
  await draw();
}

function nextMoment(after) {
  return info.moments.find((at) => at > after + 1e-9);
}

function previousMoment(before) {
  return [...info.moments].reverse().find((at) => at < before - 1e-9);
}

async function replay() {
  $("#mode").textContent = `replay of ${info.file} (${info.duration.toFixed(2)} s)`;
  $("#replay").hidden = false;
  const slider = $("#slider");
  slider.max = String(info.duration);
  slider.addEventListener("input", () => showMoment(Number(slider.value)));
  $("#forward").addEventListener("click", () => {
    const at = nextMoment(state.now);
    if (at !== undefined) showMoment(at);
  });
  $("#back").addEventListener("click", () => showMoment(previousMoment(state.now) ?? 0));
  $("#next-action").addEventListener("click", () => {
    const at = info.actions.find((time) => time > state.now + 1e-9);
    if (at !== undefined) showMoment(at);
    else $("#mode").textContent = `replay of ${info.file}: no action after ${state.now.toFixed(2)} s`;
  });
  $("#next-change").addEventListener("click", async () => {
    if (!chosen) return;
    const all = await getJson("/api/node", chosen);
    const next = all.find((each) => each.at > state.now + 1e-9);
    if (next) showMoment(next.at);
    else $("#mode").textContent = `replay of ${info.file}: the chosen node does not change after ${state.now.toFixed(2)} s`;
  });
  $("#play").addEventListener("click", () => {
    if (playing) {
      clearInterval(playing);
      playing = null;
      $("#play").innerHTML = "&#9654;";
      $("#play").setAttribute("aria-label", "play");
      return;
    }
    $("#play").innerHTML = "&#10074;&#10074;";
    $("#play").setAttribute("aria-label", "pause");
    playing = setInterval(() => {
      if (state.now >= info.duration) { $("#play").click(); return; }
      showMoment(state.now + 0.1);
    }, 100);
  });
  await showMoment(0);
}

async function start() {
  info = await getJson("/api/info");
  document.body.dataset.mode = info.mode;
  if (info.mode === "replay") await replay();
  else await live();
  document.body.dataset.ready = "true";
}

start().catch((error) => { $("#mode").textContent = `cannot load the view: ${error.message}`; });

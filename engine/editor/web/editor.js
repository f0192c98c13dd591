// The tree editor: a tree held as an outline (settings and nodes), changed from forms and
// a palette, checked by the server as you type (the checks of `vest validate`), saved as
// YAML that keeps the file's comments and layout. Undo and redo keep whole outlines.

import { cleanSvg } from "/shared/drawing.js";
import { api } from "/shared/address.js";

const $ = (selector) => document.querySelector(selector);
const make = (tag, props = {}, ...children) => {
  const element = document.createElement(tag);
  Object.assign(element, props);
  element.append(...children);
  return element;
};

let palette = { nodes: [], pads: [], joints: [], colors: [], keys: [], kinds: {} };
let profiles = {}; // profile name -> {param: value}: what each profile sets
let profileProblems = []; // "trees/profiles/x.yaml:2:3: ... (left out)": profiles that do not load
let pendingProfiles = new Map(); // "profile setting" -> [profile, setting, raw]: written at Save
let priorities = {}; // tree name -> its priority, among the folder's trees
const types = new Map(); // node type name -> its declaration
let file = null; // {name, version (null: new), outline}
let chosen = null; // the chosen node object
let undone = [];
let done = [];
let saved = ""; // the outline as last read or saved (JSON)
let checking = null;

// the tree's settings: name and description, then those the loader declares (palette)
const SETTING_LABELS = {
  rate_hz: "Looks how often (times a second)", priority: "Priority",
  wait_for_turn_s: "Waits for its turn (seconds)", when_interrupted: "When cut short",
  wake_on: "Wakes on (keys)", interruptible: "A child's voice stops its sentences",
};
const settingFields = () => [
  { name: "name", label: "Name", kind: "text", doc: "the tree's name (unique in its folder)" },
  { name: "description", label: "What it does", kind: "text", doc: "for people" },
  ...palette.settings.map((field) => ({ ...field, label: SETTING_LABELS[field.name] ?? field.name, required: false })),
];

async function getJson(path, params) {
  const response = await fetch(api(path, params));
  const body = await response.json().catch(() => ({ message: `${response.status}` }));
  if (!response.ok) throw new Error(body.message ?? `${path}: ${response.status}`);
  return body;
}

async function postJson(path, body) {
  const response = await fetch(api(path), {
    method: "POST", headers: { "content-type": "application/json" }, body: JSON.stringify(body),
  });
  return { status: response.status, body: await response.json().catch(() => ({})) };
}

// the server is gone (vest edit ended): nothing is lost on the page; saving says so
function unreachable() {
  $("#state").textContent = "cannot reach vest edit: is it still running? (changes not saved)";
}

function say(text, tone = "") {
  const box = file?.kind === "dialog" ? $("#d-message") : $("#message");
  box.textContent = text;
  box.className = tone;
}

// -- the outline --------------------------------------------------------------------------
const snapshot = () => JSON.stringify(file.outline);
const childrenOf = (type) => (type === "Subtree" ? "none" : types.get(type)?.children ?? "none");

function walk(node, visit, parent = null, path = "root") {
  visit(node, parent, path);
  const one = childrenOf(node.type) === "one";
  node.children.forEach((child, index) => walk(child, visit, node, `${path}/${one ? "child" : index}`));
}

function parentOf(target) {
  let found = null;
  walk(file.outline.root, (node, parent) => { if (node === target) found = parent; });
  return found;
}

let typingIn = null; // the field being typed in: its keystrokes are one undo step

function change(edit, redrawForm = true, field = null) { // every change: undoable, checked, drawn
  if (field === null || field !== typingIn) done.push(snapshot());
  typingIn = field;
  undone = [];
  edit();
  say("");
  changed(redrawForm);
}

// a field's own edit leaves its form as it is (the person may be typing in the next field)
function changed(redrawForm = true) {
  for (const id of ["#undo", "#d-undo"]) $(id).disabled = done.length === 0;
  for (const id of ["#redo", "#d-redo"]) $(id).disabled = undone.length === 0;
  const dirty = snapshot() !== saved || !file.version; // a new file is not saved yet
  $("#state").textContent = dirty ? "changed, not saved" : "saved";
  document.body.dataset.dirty = String(dirty);
  if (file.kind === "dialog") {
    if (redrawForm) drawRules();
  } else {
    drawOutline();
    if (redrawForm) drawNodeForm();
  }
  if (file.kind !== "dialog" && !$("#params").contains(document.activeElement)) drawParams(); // where each setting is used
  checkSoon();
}

const undo = () => { if (done.length) { undone.push(snapshot()); restore(done.pop()); } };
const redo = () => { if (undone.length) { done.push(snapshot()); restore(undone.pop()); } };

function restore(text) {
  const path = chosen && file.kind !== "dialog" ? pathOf(chosen) : null;
  file.outline = JSON.parse(text);
  chosen = path ? nodeAt(path) : null;
  typingIn = null;
  if (file.kind !== "dialog") drawSettings(); // the forms show the values undone
  changed();
}

function pathOf(target) {
  let found = null;
  walk(file.outline.root, (node, _, path) => { if (node === target) found = path; });
  return found;
}

function nodeAt(path) {
  let found = null;
  walk(file.outline.root, (node, _, at) => { if (at === path) found = node; });
  return found;
}

let leafWords = new Map(); // a leaf's place -> what it does in words (the server says it)

function summary(node, path) { // "in order (Sequence)", "say “Hello” (Say)"
  const said = leafWords.get(path);
  if (said) return `${node.name ? `${node.name}: ` : ""}${said} (${node.type})`;
  const words = types.get(node.type)?.words;
  const what = words ? `${words} (${node.type})` : node.type;
  const args = Object.entries(node.args).map(([key, value]) => `${key}: ${shown(value)}`);
  return [node.name ? `${node.name}: ${what}` : what, ...args].join(", ");
}

const shown = (value) => (Array.isArray(value) ? value.join(", ") : typeof value === "object" && value !== null ? JSON.stringify(value) : String(value));

let problemsByNode = new Map();

function drawOutline() {
  const list = $("#outline");
  const item = (node, path, depth) => {
    const row = make("li", { role: "treeitem" });
    row.setAttribute("aria-level", String(depth));
    row.setAttribute("aria-selected", String(node === chosen));
    const kind = types.get(node.type)?.kind ?? "action";
    const button = make("button", { type: "button", className: `node kind-${kind}` });
    button.dataset.path = path;
    button.append(make("span", { className: "what", textContent: summary(node, path) }));
    const problems = problemsByNode.get(path) ?? [];
    if (problems.length) {
      button.append(make("span", { className: "badge", textContent: `${problems.length} problem${problems.length > 1 ? "s" : ""}` }));
    }
    button.addEventListener("click", () => { chosen = node; drawOutline(); drawNodeForm(); });
    row.append(button);
    if (node.children.length) {
      const group = make("ul", { role: "group" });
      const one = childrenOf(node.type) === "one";
      node.children.forEach((child, index) => group.append(item(child, `${path}/${one ? "child" : index}`, depth + 1)));
      row.append(group);
    }
    return row;
  };
  const focused = document.activeElement?.closest?.("#outline") ? document.activeElement.dataset.path : null;
  list.replaceChildren(item(file.outline.root, "root", 1));
  if (focused) list.querySelector(`[data-path="${CSS.escape(focused)}"]`)?.focus(); // the list was drawn anew
  const parent = chosen ? parentOf(chosen) : null;
  $("#add-inside").disabled = !chosen || childrenOf(chosen.type) === "none"
    || (childrenOf(chosen.type) === "one" && chosen.children.length > 0);
  $("#add-after").disabled = !parent || childrenOf(parent.type) !== "many";
  $("#delete").disabled = !chosen || !parent;
  const index = parent ? parent.children.indexOf(chosen) : -1;
  $("#move-up").disabled = !parent || index <= 0;
  $("#move-down").disabled = !parent || index >= parent.children.length - 1;
  $("#move-out").disabled = !parent || !parentOf(parent) || childrenOf(parentOf(parent).type) !== "many";
}

// -- forms ---------------------------------------------------------------------------------
// A value as typed becomes what YAML would hold: a number where a number is meant (but a
// ${param} stays text), a list from commas; an empty field is no value at all.
function typed(text, field) {
  const trimmed = text.trim();
  if (trimmed === "") return undefined;
  if (field.kind === "list") return trimmed.split(",").map((part) => typed(part, field.item ?? { kind: "any" })).filter((v) => v !== undefined);
  if (["number", "integer", "any"].includes(field.kind) && /^-?\d+(\.\d+)?$/.test(trimmed)) return Number(trimmed);
  if (field.kind === "any" && (trimmed === "true" || trimmed === "false")) return trimmed === "true";
  return trimmed;
}

function fieldFor(field, value, set, idPrefix) {
  const id = `${idPrefix}-${field.name}`;
  const wrap = make("div", { className: "field" });
  const range = field.min !== undefined || field.max !== undefined
    ? ` ${field.min ?? ""}..${field.max ?? ""}` : "";
  const unit = field.unit ? ` ${field.unit}` : "";
  const label = make("label", { htmlFor: id, textContent: `${field.label ?? field.name.replaceAll("_", " ")}${field.required ? " (needed)" : ""}` });
  const from = typeof value === "string" ? /^\$\{(\w+)\}$/.exec(value)?.[1] : undefined;
  const help = make("p", { className: "help", id: `${id}-help`, textContent: `${field.doc ?? ""}${range || unit ? ` (${(range + unit).trim()})` : ""}${from ? `. ${settingSaid(from)}` : ""}` });
  let input;
  const words = field.words ? palette[field.words] ?? [] : [];
  if (field.kind === "list" && words.length) { // the robot's pads: tick the ones meant
    input = make("fieldset", { id, className: "choices" });
    input.append(make("legend", { textContent: label.textContent }));
    const chosenWords = new Set(Array.isArray(value) ? value : []);
    for (const word of words) {
      const box = make("input", { type: "checkbox", id: `${id}-${word}`, checked: chosenWords.has(word) });
      box.addEventListener("change", () => {
        const now = words.filter((w) => (w === word ? box.checked : chosenWords.has(w)));
        if (box.checked) chosenWords.add(word); else chosenWords.delete(word);
        set(now.length ? now : undefined);
      });
      input.append(make("label", { htmlFor: box.id, className: "choice" }, box, ` ${word}`));
    }
    input.setAttribute("aria-describedby", help.id);
    wrap.append(input, help);
    return wrap;
  }
  if (field.kind === "choice" || field.kind === "boolean") {
    input = make("select", { id });
    const options = field.kind === "boolean" ? ["true", "false"] : field.options;
    input.append(make("option", { value: "", textContent: field.default !== undefined ? `(default: ${field.default})` : "(none)" }));
    for (const option of options) input.append(make("option", { value: option, textContent: option, selected: String(value) === option }));
    input.addEventListener("change", () => set(input.value === "" ? undefined : field.kind === "boolean" ? input.value === "true" : input.value));
  } else {
    input = make("input", { id, type: "text", value: value === undefined ? "" : shown(value) });
    if (field.kind === "number" || field.kind === "integer") input.inputMode = "decimal";
    const suggestions = words.length ? words : field.kind === "key" || field.item?.kind === "key" ? palette.keys : [];
    if (suggestions.length) {
      const listId = `${id}-words`;
      input.setAttribute("list", listId);
      wrap.append(make("datalist", { id: listId }, ...suggestions.map((word) => make("option", { value: word }))));
    }
    if (field.default !== undefined) input.placeholder = `default: ${shown(field.default)}`;
    const setting = typeof value === "string" ? /^\$\{(\w+)\}$/.exec(value)?.[1] : undefined;
    if (setting !== undefined) { // set by the tree's setting, which profiles change: ask first
      input.addEventListener("change", () => {
        const now = typed(input.value, field);
        const replaces = typeof now !== "string" || !now.includes("${");
        if (replaces && !confirm(`Replace \${${setting}} with ${now ?? "nothing"}? `
          + `${settingSaid(setting)}; what you type here is the same for every profile.`)) {
          input.value = value; // kept: the profile still decides
          return;
        }
        set(now);
      });
    } else {
      input.addEventListener("input", () => set(typed(input.value, field), id)); // as you type
    }
    input.addEventListener("blur", () => { if (typingIn === id) typingIn = null; });
  }
  input.setAttribute("aria-describedby", help.id);
  wrap.prepend(label);
  wrap.append(input, help);
  return wrap;
}

function drawSettings() {
  const box = $("#settings");
  box.replaceChildren(make("legend", { textContent: "The tree" }));
  const settings = file.outline.settings;
  for (const field of settingFields()) {
    box.append(fieldFor(field, settings[field.name], (value, typing = null) => change(() => {
      if (value === undefined) delete settings[field.name]; else settings[field.name] = value;
    }, false, typing), "setting"));
  }
  drawParams();
  drawPriorityHelp();
}

// -- the tree's settings a profile can change (its params) ----------------------------------
// Each is shown as a field with the unit and range of where the tree uses it, and what each
// profile sets it to.
// a new setting: its name and the tree's own value; a node's field then says ${name}
function addSettingForm(names) {
  const wanted = unknownSettings().filter((name) => !names.includes(name));
  const typed = { name: $("#new-setting-name")?.value ?? "", value: $("#new-setting-value")?.value ?? "" };
  const row = make("div", { className: "add-setting" });
  const name = make("input", { id: "new-setting-name", type: "text", maxLength: 60, value: typed.name && !names.includes(typed.name) ? typed.name : wanted[0] ?? "", placeholder: "left_squeeze_n" });
  const value = make("input", { id: "new-setting-value", type: "text", maxLength: 60, value: typed.value, placeholder: "3" });
  const add = make("button", { type: "button", textContent: "Add the setting" });
  add.addEventListener("click", () => addSetting(name.value.trim(), value.value.trim()));
  row.append(
    make("label", { htmlFor: "new-setting-name", textContent: "New setting" }), " ", name, " ",
    make("label", { htmlFor: "new-setting-value", textContent: "its value here" }), " ", value, " ", add,
    make("p", { className: "help", id: "new-setting-help", textContent: "A node's value written ${name} (e.g. above: ${left_squeeze_n}) is this setting: the tree's own value, which each profile may change." }),
  );
  return row;
}

function unknownSettings() { // ${name}s the nodes use that the tree does not declare
  const declared = file.outline.params ?? {};
  const found = new Set();
  walk(file.outline.root, (node) => {
    for (const value of Object.values(node.args)) {
      if (typeof value !== "string") continue;
      for (const [, name] of value.matchAll(/\$\{([A-Za-z_][A-Za-z0-9_]*)\}/g)) if (!(name in declared)) found.add(name);
    }
  });
  return [...found];
}

function addSetting(name, raw) {
  if (!/^[A-Za-z_][A-Za-z0-9_]*$/.test(name)) {
    say("A setting's name is letters, digits and _ (no spaces), e.g. left_squeeze_n", "problem");
    return;
  }
  if (name in (file.outline.params ?? {})) { say(`The tree already has the setting ${name}.`, "problem"); return; }
  if (raw === "") { say(`Give ${name} its value here (a profile may change it), e.g. 3`, "problem"); return; }
  const value = raw !== "" && !Number.isNaN(Number(raw)) ? Number(raw) : raw === "true" ? true : raw === "false" ? false : raw;
  change(() => { file.outline.params = { ...(file.outline.params ?? {}), [name]: value }; });
  $("#new-setting-name").value = ""; $("#new-setting-value").value = ""; // added: start afresh
  drawParams();
  $(`#param-${name}`)?.focus?.();
}

function usesOf(name) { // the node fields that hold ${name}
  const found = [];
  walk(file.outline.root, (node) => {
    for (const [arg, value] of Object.entries(node.args)) {
      if (typeof value === "string" && value.includes(`\${${name}}`)) {
        const field = types.get(node.type)?.params?.find((p) => p.name === arg);
        found.push({ node: node.type, arg, field });
      }
    }
  });
  return found;
}

function settingSaid(name) { // "Set by the tree's setting hug_threshold_n: 3 here; child: 2"
  const here = file.outline.params?.[name];
  const set = Object.entries(profiles).filter(([, values]) => name in values)
    .map(([profile, values]) => `${profile}: ${shown(values[name])}`);
  const by = set.length ? `; profiles: ${set.join(", ")}` : "; no profile changes it";
  return `Set by the tree's setting ${name} (${here === undefined ? "not set" : shown(here)} here${by})`;
}

function drawParams() {
  const box = $("#params");
  const params = file.outline.params ?? {};
  const names = Object.keys(params);
  box.hidden = false;
  box.replaceChildren(make("legend", { textContent: "Settings a profile can change" }));
  box.append(addSettingForm(names));
  for (const name of names) {
    const uses = usesOf(name);
    const like = uses.find((use) => use.field)?.field ?? { kind: "any" };
    const where = uses.length ? `used by ${uses.map((use) => `${use.node} ${use.arg}`).join(", ")}` : "not used by any node";
    const set = Object.entries(profiles).map(([profile, values]) => {
      const held = pendingProfiles.get(`${profile} ${name}`); // typed, written at Save
      if (held) return held[2] === "" ? null : `${profile}: ${held[2]} (when you save)`;
      return name in values ? `${profile}: ${shown(values[name])}` : null;
    }).filter(Boolean);
    const field = {
      ...like, name, label: name.replaceAll("_", " "), required: true,
      doc: `${where}; ${set.length ? `profiles set it: ${set.join(", ")}` : "no profile changes it"}`,
    };
    delete field.default;
    box.append(fieldFor(field, params[name], (value, typing = null) => change(() => {
      if (value === undefined) delete params[name]; else params[name] = value;
    }, false, typing), "param"));
    box.append(profileValues(name));
  }
  for (const problem of profileProblems) box.append(make("p", { className: "problem", textContent: problem }));
}

// what each profile sets a setting to, changed here and written to the profile's own file
function profileValues(name) {
  const row = make("div", { className: "profile-values" });
  for (const [profile, values] of Object.entries(profiles)) {
    const id = `profile-${profile}-${name}`;
    const held = pendingProfiles.get(`${profile} ${name}`);
    const value = held ? held[2] : values[name] === undefined ? "" : shown(values[name]);
    const input = make("input", { id, type: "text", maxLength: 60, value, placeholder: "the tree's own" });
    input.addEventListener("change", () => changeProfile(profile, name, input.value.trim()));
    row.append(make("label", { htmlFor: id, textContent: `${profile} profile` }), " ", input, " ");
  }
  return row;
}

// a profile may only set what a saved tree declares (vest validate and the robot refuse
// the rest): while the tree has changes, what is typed for a profile waits for Save
function changeProfile(profile, setting, raw) {
  if (document.body.dataset.dirty !== "true") { setInProfile(profile, setting, raw).catch(unreachable); return; }
  pendingProfiles.set(`${profile} ${setting}`, [profile, setting, raw]);
  drawParams();
  say(`The ${profile} profile will set ${setting} to ${raw || "the tree's own value"} when you save the tree (its file is written then).`);
}

async function savePendingProfiles() {
  const pending = [...pendingProfiles.values()];
  pendingProfiles = new Map();
  for (const [profile, setting, raw] of pending) await setInProfile(profile, setting, raw);
  return pending.length;
}

async function setInProfile(profile, setting, raw) {
  const value = raw === "" ? null : !Number.isNaN(Number(raw)) ? Number(raw) : raw === "true" ? true : raw === "false" ? false : raw;
  const { status, body } = await postJson("/api/profile", { profile, setting, value });
  if (status !== 200) { say(body.message ?? `the ${profile} profile was not changed (${status})`, "problem"); return; }
  ({ profiles, problems: profileProblems } = body);
  say(value === null ? `The ${profile} profile no longer sets ${setting}: the tree's own value holds.` : `The ${profile} profile now sets ${setting} to ${raw} (saved in its file).`);
  drawParams();
}

function drawNodeForm() {
  const form = $("#node-form");
  $("#no-node").hidden = Boolean(chosen);
  form.hidden = !chosen;
  if (!chosen) return;
  const node = chosen;
  const declared = types.get(node.type);
  const fields = [{ name: "name", kind: "text", doc: "a name people read in drawings (optional)" }, ...(declared?.params ?? [])];
  form.replaceChildren(
    make("h3", { textContent: declared?.words ? `${declared.words} (${node.type})` : node.type }),
    make("p", { className: "help", textContent: declared?.summary ?? "a node this robot does not know" }),
    declared?.doc && declared.doc !== declared.summary
      ? make("details", {}, make("summary", { textContent: "more about it" }), make("p", { className: "help", textContent: declared.doc.replaceAll("``", "") }))
      : "",
    make("div", { id: "node-problems", role: "status" }),
    ...fields.map((field) => fieldFor(field, field.name === "name" ? node.name ?? undefined : node.args[field.name], (value, typing = null) => change(() => {
      if (field.name === "name") node.name = value ?? null;
      else node.args = inDeclaredOrder({ ...node.args, [field.name]: value }, declared);
    }, false, typing), "node")),
  );
  drawNodeProblems();
}

function drawNodeProblems() {
  const box = $("#node-problems");
  if (!box || !chosen) return;
  const problems = problemsByNode.get(pathOf(chosen)) ?? [];
  box.replaceChildren(...problems.map((problem) => make("p", { className: "problem", textContent: problemText(problem) })));
}

// a node's parameters in the order its declaration gives them (as `vest nodes` lists them)
function inDeclaredOrder(args, declared) {
  const order = (declared?.params ?? []).map((param) => param.name);
  const rank = (name) => (order.includes(name) ? order.indexOf(name) : order.length);
  return Object.fromEntries(Object.entries(args).filter(([, value]) => value !== undefined)
    .sort(([a], [b]) => rank(a) - rank(b)));
}

const problemText = (problem) => `line ${problem.line}: ${problem.message}${problem.hint ? ` (${problem.hint})` : ""}`;

// -- checking and drawing -------------------------------------------------------------------
function checkSoon() {
  clearTimeout(checking);
  checking = setTimeout(() => check().catch(unreachable), 250);
}

async function check() {
  const asked = snapshot();
  const { status, body } = await postJson("/api/check", { file: file.name, outline: file.outline, version: file.version });
  if (asked !== snapshot()) return; // changed again meanwhile: that check comes
  if (status !== 200) { say(body.message ?? `the check failed (${status})`, "bad"); return; }
  if (file.kind === "dialog") {
    $("#d-problems").replaceChildren(...(body.problems.length
      ? body.problems.map((problem) => make("li", { className: "problem", textContent: problemText(problem) }))
      : [make("li", { className: "fine", textContent: "none: vest validate accepts this dialog" })]));
    document.body.dataset.problems = String(body.problems.length);
    return;
  }
  leafWords = new Map(Object.entries(body.words ?? {}));
  problemsByNode = new Map();
  for (const problem of body.problems) {
    const list = problemsByNode.get(problem.node) ?? [];
    list.push(problem);
    problemsByNode.set(problem.node, list);
  }
  $("#problems").replaceChildren(...(body.problems.length ? body.problems.map((problem) => {
    const item = make("li", { className: "problem" });
    const where = problem.node ? nodeAt(problem.node) : null;
    if (where) {
      const go = make("button", { type: "button", textContent: problemText(problem) });
      go.addEventListener("click", () => { chosen = where; drawOutline(); drawNodeForm(); $("#node-panel").focus(); });
      item.append(go);
    } else item.textContent = `${problem.here ? "" : `${problem.file}: `}${problemText(problem)}`;
    return item;
  }) : [make("li", { className: "fine", textContent: "none: vest validate accepts this tree" })]));
  document.body.dataset.problems = String(body.problems.length);
  if (body.svg) {
    $("#drawing").replaceChildren(cleanSvg(body.svg));
  } else if (body.problems.length) {
    $("#drawing").textContent = "(drawn once the problems are fixed)";
  }
  drawOutline();
  drawNodeProblems();
}

// -- the toolbar ------------------------------------------------------------------------------
let adding = null; // "inside" or "after"

function openPalette(where) {
  adding = where;
  $("#palette-filter").value = "";
  drawPalette("");
  $("#palette").showModal();
  $("#palette-filter").focus();
}

function drawPalette(filter) {
  const groups = $("#palette-groups");
  const wanted = filter.trim().toLowerCase();
  // a word of the robot's senses ("squeeze", "pat"): the blackboard keys that hold it, and
  // the nodes that read a key, which ask about them
  const named = (node) => `${node.name} ${node.words ?? ""} ${node.summary}`.toLowerCase().includes(wanted);
  const found = !wanted || palette.nodes.some(named);
  // the words people use for what a sense measures: a squeeze or a hug is a side's force
  const sense = { squeeze: "/sensors/force/", hug: "/sensors/force/", press: "/sensors/force/", pat: "/sensors/touch/" }[wanted];
  const keys = found || wanted.length < 3 ? [] : palette.keys.filter((key) => key.toLowerCase().includes(wanted) || (sense && key.startsWith(sense)));
  // a node that asks about any key names it "key" (Check, Fresh, OnEvent, WaitForEvent)
  const readsKeys = (node) => keys.length && node.params.some((param) => param.name === "key" && param.kind === "key" && param.access !== "write");
  const sensed = keys.length
    ? [make("p", { className: "palette-keys", textContent: `"${filter.trim()}" is on the blackboard as ${keys.slice(0, 6).join(", ")}${keys.length > 6 ? "..." : ""}: the nodes below ask about it (choose the key in the node's form; a threshold a profile sets is a Check of a side's force, /sensors/force/left_n or right_n, in newtons).` })]
    : [];
  groups.replaceChildren(...sensed, ...Object.entries(palette.kinds).map(([kind, words]) => {
    const nodes = palette.nodes.filter((node) => node.kind === kind
      && (!wanted || readsKeys(node) || named(node)));
    if (!nodes.length) return "";
    return make("section", {}, make("h3", { textContent: words }), ...nodes.map((node) => {
      const button = make("button", { type: "button", className: "palette-node" },
        make("strong", { textContent: node.words ? `${node.words} (${node.name})` : node.name }), ` ${node.summary}`);
      button.dataset.node = node.name;
      button.addEventListener("click", () => { $("#palette").close(); add(node); });
      return button;
    }));
  }));
}

function add(declared) {
  const node = { type: declared.name, name: null, args: {}, children: [] };
  for (const param of declared.params) if (param.required && param.default !== undefined) node.args[param.name] = param.default;
  change(() => {
    if (adding === "inside") chosen.children.push(node);
    else { const parent = parentOf(chosen); parent.children.splice(parent.children.indexOf(chosen) + 1, 0, node); }
    chosen = node;
  });
  $("#node-panel").focus();
}

function move(step) {
  const parent = parentOf(chosen);
  const index = parent.children.indexOf(chosen);
  change(() => { parent.children.splice(index, 1); parent.children.splice(index + step, 0, chosen); });
}

function moveOut() {
  const parent = parentOf(chosen);
  const grand = parentOf(parent);
  change(() => {
    parent.children.splice(parent.children.indexOf(chosen), 1);
    grand.children.splice(grand.children.indexOf(parent) + 1, 0, chosen);
  });
}

function remove() {
  const parent = parentOf(chosen);
  change(() => { parent.children.splice(parent.children.indexOf(chosen), 1); chosen = parent; });
}

async function save(overProblems = false) {
  const { status, body } = await postJson("/api/save", {
    file: file.name, outline: file.outline, version: file.version, over_problems: overProblems,
  });
  if (status === 200) {
    const message = `saved ${file.name}${body.problems.length ? ` with ${body.problems.length} problems` : ""}`;
    await open(file.name, true);
    const profilesSet = await savePendingProfiles();
    say(profilesSet ? `${message}, and the profiles' values (${profilesSet})` : message, "good");
    await listFiles();
    return;
  }
  if (status === 409 && body.problems?.length) {
    $("#confirm-text").textContent = body.message;
    $("#confirm").returnValue = "";
    $("#confirm").showModal();
    $("#confirm").addEventListener("close", () => { if ($("#confirm").returnValue === "yes") save(true).catch(unreachable); }, { once: true });
    return;
  }
  say(body.message ?? `not saved (${status})`, "bad");
}

// -- a try on the simulated vest -------------------------------------------------------------
function tryKindChanged() {
  const kind = $("#try-kind").value;
  $("#try-pad-field").hidden = kind !== "pat";
  $("#try-text-field").hidden = kind !== "say";
  $("#try-strength-field").hidden = kind !== "squeeze";
  $("#try-side-field").hidden = kind !== "squeeze";
  $("#try-seconds-field").hidden = kind !== "pat" && kind !== "squeeze";
  $("#try-seconds").placeholder = kind === "squeeze" ? "2" : "0.3";
  tryApartShown();
}

function tryApartShown() { // the distance the try makes when Apart is left empty
  const kind = $("#try-kind").value;
  const lasts = number("#try-seconds") ?? { pat: 0.3, squeeze: 2 }[kind] ?? 0;
  $("#try-apart").placeholder = String(Math.max(1.5, lasts + 1));
}

const number = (id) => ($(id).value.trim() === "" ? undefined : Number($(id).value));

function askedTry() { // what the form asks for, and the same in words
  const kind = $("#try-kind").value;
  const asked = {
    kind, pad: $("#try-pad").value, text: $("#try-text").value, strength_n: number("#try-strength"),
    seconds: number("#try-seconds"), times: number("#try-times"), apart_s: number("#try-apart"),
    side: $("#try-side").value, profile: $("#try-profile").value,
  };
  const times = asked.times ?? 1;
  const side = { both: "both sides", left: "the left side pad", right: "the right side pad" }[asked.side];
  const what = { pat: `a pat on ${asked.pad}`, squeeze: `a squeeze of ${asked.strength_n ?? 6} N on ${side}`, say: `"${asked.text}" said`, wave: "a wave" }[kind];
  const lasts = asked.seconds ?? { pat: 0.3, squeeze: 2 }[kind] ?? 0; // as the try does
  const apart = asked.apart_s ?? Math.max(1.5, lasts + 1); // each one over before the next
  const said = times > 1 ? `${times} times: ${what}, ${apart} s apart` : what;
  const as = asked.profile ? `, with the ${asked.profile} profile's settings` : ", with the trees' own settings";
  return { asked, said: said + as };
}

async function tryIt(event) {
  event.preventDefault();
  const { asked, said } = askedTry();
  $("#tried-what").textContent = `Tried on ${file.name}, among the folder's other trees: ${said}`;
  $("#tried").replaceChildren(make("li", { textContent: "trying on the simulated vest..." }));
  const { status, body } = await postJson("/api/try", { file: file.name, outline: file.outline, version: file.version, event: asked });
  if (status !== 200) {
    $("#tried").replaceChildren(make("li", { className: "problem", textContent: body.message ?? `the try failed (${status})` }));
    return;
  }
  const lines = body.timeline.length ? body.timeline : ["nothing happened"];
  $("#tried").replaceChildren(...lines.map((line) => make("li", { textContent: line })));
}

// the same in real time under the live view: a link to open it (the event comes at 5 s)
async function watchIt() {
  const { asked } = askedTry();
  $("#watching").textContent = "starting the simulated vest...";
  const { status, body } = await postJson("/api/watch", { file: file.name, outline: file.outline, version: file.version, event: asked });
  if (status !== 200) { $("#watching").textContent = body.message ?? `cannot watch (${status})`; return; }
  const link = make("a", { href: body.url, target: "_blank", rel: "noopener", textContent: "Open the live view" });
  $("#watching").replaceChildren(link, " : the tree runs for 30 s on the simulated vest; what you chose happens 5 s after you pressed Watch.");
  link.focus();
}

// -- files --------------------------------------------------------------------------------------
async function listFiles() {
  const files = await getJson("/api/files");
  const groups = new Map();
  for (const each of files) groups.set(each.kind, [...(groups.get(each.kind) ?? []), each]);
  $("#files").replaceChildren(...[...groups.entries()].map(([kind, list]) => make("section", {},
    make("h3", { textContent: `${kind}${kind.endsWith("s") ? "" : "s"}` }),
    make("ul", {}, ...list.map((each) => {
      const button = make("button", { type: "button", textContent: each.file });
      button.addEventListener("click", () => leave() && open(each.file).catch((error) => say(error.message, "bad")));
      return make("li", {}, button);
    })))));
}

const leave = () => document.body.dataset.dirty !== "true" || confirm("Leave this tree? Its changes are not saved.");

async function loadProfiles() { // what each profile sets, read again: a profile may have changed
  ({ profiles, problems: profileProblems } = await getJson("/api/profiles"));
  const chosen = $("#try-profile").value;
  $("#try-profile").replaceChildren(
    make("option", { value: "", textContent: "the tree's own" }),
    ...Object.keys(profiles).map((name) => make("option", { value: name, textContent: `the ${name} profile's` })),
  );
  $("#try-profile").value = chosen in profiles ? chosen : "";
}

async function open(name, keepMessage = false) {
  if (!keepMessage) pendingProfiles = new Map(); // another tree: what waited for its Save goes
  await loadProfiles();
  const read = await getJson("/api/file", { name });
  if (!keepMessage) say("");
  if (read.kind === "dialog") {
    start({ name, kind: "dialog", version: read.version, outline: read.outline });
    return;
  }
  if (!read.outline) {
    $("#editing").hidden = true; $("#dialog-editing").hidden = true; $("#nothing").hidden = true; $("#as-text").hidden = false;
    $("#text-name").textContent = name;
    $("#text-why").textContent = `Not a tree (${read.why_not}): shown as it is; edit it by hand.`;
    $("#text").textContent = read.text;
    file = null;
    return;
  }
  start({ name, version: read.version, outline: read.outline });
}

function start(opened) {
  file = opened;
  saved = snapshot();
  done = []; undone = [];
  const dialog = file.kind === "dialog";
  chosen = dialog ? null : file.outline.root;
  $("#nothing").hidden = true; $("#as-text").hidden = true;
  $("#editing").hidden = dialog; $("#dialog-editing").hidden = !dialog;
  $(dialog ? "#dialog-name" : "#file-name").textContent = file.name + (file.version ? "" : " (new)");
  $("#heard").replaceChildren();
  $("#tried").replaceChildren(); $("#tried-what").textContent = ""; // a try belongs to its tree
  $("#watching").replaceChildren();
  if (!dialog) {
    drawSettings();
    getJson("/api/priorities").then((found) => { priorities = found; drawPriorityHelp(); }).catch(unreachable);
  }
  changed();
}

// what a priority means among the folder's other trees (the buttons are 100)
function drawPriorityHelp() {
  const help = $("#setting-priority-help");
  if (!help || !file?.outline?.settings) return;
  const own = file.outline.settings.name;
  const others = Object.entries(priorities).filter(([name]) => name !== own).sort((a, b) => b[1] - a[1]);
  if (!others.length) return;
  const lowest = Math.min(...others.map(([, p]) => p));
  const highest = Math.max(...others.map(([, p]) => p));
  help.textContent = `0..99: higher interrupts lower for the speaker, the face lights or a joint. `
    + `Other trees: ${others.map(([name, p]) => `${name} ${p}`).join(", ")}; the therapist's buttons 100. `
    + `${lowest > 0 ? `At ${lowest - 1} or lower this tree never interrupts another one that is speaking or moving; ` : ""}`
    + `above ${highest} it interrupts them all but the buttons.`;
}

// -- a dialog: questions and their answers -------------------------------------------------------
function drawRules() {
  $("#rules").replaceChildren(...file.outline.rules.map((rule, index) => {
    const box = make("fieldset", { className: "rule" });
    box.append(make("legend", { textContent: `Question ${index + 1}${rule.rule ? `: ${rule.rule}` : ""}` }));
    const id = `rule-${index}`;
    const text = (label, key, value, multi) => {
      const input = make(multi ? "textarea" : "input", { id: `${id}-${key}`, value, rows: 3 });
      input.addEventListener("change", () => change(() => {
        rule[key] = multi ? input.value.split("\n").map((line) => line.trim()).filter(Boolean) : input.value.trim();
      }, false));
      return make("div", { className: "field" }, make("label", { htmlFor: input.id, textContent: label }), input);
    };
    box.append(
      text("Its name (a word)", "rule", rule.rule ?? "", false),
      text("A person says (one way of asking per line)", "hear", (rule.hear ?? []).join("\n"), true),
      text("The robot answers", "say", rule.say ?? "", false),
    );
    if (rule.more) box.append(make("p", { className: "help", textContent: "It also asks back or reads a sensor: that part is kept as written (edit it by hand)." }));
    const remove = make("button", { type: "button", textContent: `Delete question ${index + 1}` });
    remove.addEventListener("click", () => change(() => file.outline.rules.splice(index, 1)));
    box.append(remove);
    return box;
  }));
}

function addRule() {
  change(() => file.outline.rules.push({ rule: "", hear: [], say: "" }));
  $(`#rule-${file.outline.rules.length - 1}-rule`).focus();
}

async function hear() {
  $("#heard").replaceChildren(make("li", { textContent: "saying each phrase and hearing it (about 20 s)..." }));
  const { status, body } = await postJson("/api/hear", { file: file.name, outline: file.outline, version: file.version });
  const lines = status === 200 ? body.lines : [body.message ?? `the check failed (${status})`];
  $("#heard").replaceChildren(...lines.map((line) => make("li", { textContent: line, className: /problem|ambiguous|heard as/.test(line) && !/ 0 problem/.test(line) ? "problem" : "" })));
}

function newTree(event) {
  event.preventDefault();
  if (!leave()) return;
  const name = $("#new-name").value.trim();
  start({
    name: `trees/${name}.yaml`, version: null,
    outline: { settings: { name, rate_hz: 20, description: "" }, root: { type: "Sequence", name: null, args: {}, children: [] } },
  });
  $("#file-name").focus?.();
}

async function main() {
  palette = await getJson("/api/palette");
  await loadProfiles();
  for (const node of palette.nodes) types.set(node.name, node);
  $("#where").textContent = "";
  await listFiles();
  $("#state").textContent = "ready";
  $("#new-tree").addEventListener("submit", newTree);
  for (const id of ["#undo", "#d-undo"]) $(id).addEventListener("click", undo);
  for (const id of ["#redo", "#d-redo"]) $(id).addEventListener("click", redo);
  $("#add-rule").addEventListener("click", addRule);
  $("#d-save").addEventListener("click", () => save().catch(unreachable));
  $("#hear").addEventListener("click", () => hear().catch(unreachable));
  $("#add-inside").addEventListener("click", () => openPalette("inside"));
  $("#add-after").addEventListener("click", () => openPalette("after"));
  $("#move-up").addEventListener("click", () => move(-1));
  $("#move-down").addEventListener("click", () => move(1));
  $("#move-out").addEventListener("click", moveOut);
  $("#delete").addEventListener("click", remove);
  $("#save").addEventListener("click", () => save().catch(unreachable));
  $("#palette-filter").addEventListener("input", (event) => drawPalette(event.target.value));
  $("#palette-filter").addEventListener("keydown", (event) => {
    if (event.key !== "Enter") return;
    event.preventDefault(); // not the dialog's form: the first node found is added
    $("#palette-groups .palette-node")?.click();
  });
  $("#try-pad").replaceChildren(...palette.pads.map((pad) => make("option", { value: pad, textContent: pad })));
  $("#try-kind").addEventListener("change", tryKindChanged);
  $("#try-seconds").addEventListener("input", tryApartShown);
  $("#try").addEventListener("submit", (event) => tryIt(event).catch(unreachable));
  $("#watch").addEventListener("click", () => watchIt().catch(unreachable));
  document.addEventListener("keydown", (event) => {
    if (!file || !(event.ctrlKey || event.metaKey)) return;
    const key = event.key.toLowerCase();
    if (key === "z") { event.preventDefault(); undo(); }
    if (key === "y") { event.preventDefault(); redo(); }
    if (key === "s") { event.preventDefault(); save().catch(unreachable); }
  });
  addEventListener("beforeunload", (event) => { if (document.body.dataset.dirty === "true") event.preventDefault(); });
  document.body.dataset.ready = "true";
}

main().catch((error) => { $("#state").textContent = `cannot load the editor: ${error.message}`; });

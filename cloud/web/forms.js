// The command form: fields built from the robot's command types (their declared arguments),
// and read back into {type, args} with a message naming the field when one is wrong.

const OTHER = "other";

function el(tag, props = {}, ...children) {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children);
  return node;
}

function kindOf(schema) {
  if (schema.enum) return "choice";
  if (schema.anyOf) return "suggest";
  const type = Array.isArray(schema.type) ? schema.type[0] : schema.type;
  return type === "number" || type === "integer" ? "number" : "text";
}

function field(commandType, param) {
  const id = `arg-${param.name}`;
  const label = el("label", { htmlFor: id, textContent: param.name + (param.required ? "" : " (optional)") });
  let input;
  const kind = kindOf(param.schema);
  if (kind === "choice") {
    input = el("select", { id, name: param.name });
    input.append(...param.schema.enum.map((v) => el("option", { value: v, textContent: v })));
  } else if (commandType === "say" && param.name === "text") {
    input = el("textarea", { id, name: param.name, maxLength: param.schema.maxLength || 1000 });
  } else {
    input = el("input", { id, name: param.name, type: kind === "number" ? "number" : "text" });
    if (kind === "number") {
      input.step = "any";
      if (param.schema.minimum !== undefined) input.min = param.schema.minimum;
      if (param.schema.maximum !== undefined) input.max = param.schema.maximum;
    }
    if (kind === "suggest") {
      const options = param.schema.anyOf.flatMap((s) => s.enum || []);
      const list = el("datalist", { id: `${id}-list` });
      list.append(...options.map((v) => el("option", { value: v })));
      input.setAttribute("list", list.id);
      label.append(list);
    }
  }
  input.required = param.required;
  input.dataset.kind = kind;
  return [label, input, el("p", { className: "field-hint", textContent: param.doc })];
}

export function typeOptions(select, catalogue) {
  select.replaceChildren(
    ...Object.keys(catalogue).map((t) => el("option", { value: t, textContent: t })),
    el("option", { value: OTHER, textContent: "other (a plugin's type)" }),
  );
}

export function buildArgs(container, commandType, catalogue) {
  if (commandType === OTHER) {
    container.replaceChildren(
      el("label", { htmlFor: "arg-type", textContent: "type" }),
      el("input", { id: "arg-type", name: "type", required: true, placeholder: "e.g. dance" }),
      el("label", { htmlFor: "arg-json", textContent: "args (JSON object)" }),
      el("textarea", { id: "arg-json", name: "args", value: "{}" }),
    );
    return;
  }
  container.replaceChildren(...catalogue[commandType].flatMap((p) => field(commandType, p)));
}

// {type, args}; throws Error("field: what is wrong") for a value the robot would refuse.
export function readCommand(container, commandType, catalogue) {
  if (commandType === OTHER) {
    const type = container.querySelector("#arg-type").value.trim();
    if (!/^[a-z][a-z0-9_]*$/.test(type)) throw new Error("type: use lower-case letters, digits and _");
    let args;
    try {
      args = JSON.parse(container.querySelector("#arg-json").value || "{}");
    } catch (error) {
      throw new Error(`args: not JSON (${error.message})`);
    }
    if (args === null || typeof args !== "object" || Array.isArray(args)) throw new Error("args: must be a JSON object");
    return { type, args };
  }
  const args = {};
  for (const param of catalogue[commandType]) {
    const input = container.querySelector(`[name="${param.name}"]`);
    const raw = input.value.trim();
    if (raw === "") {
      if (param.required) throw new Error(`${param.name}: needed`);
      continue;
    }
    if (input.dataset.kind === "number") {
      const value = Number(raw);
      const { minimum, maximum } = param.schema;
      if (!Number.isFinite(value)) throw new Error(`${param.name}: not a number`);
      if (minimum !== undefined && value < minimum) throw new Error(`${param.name}: at least ${minimum}`);
      if (maximum !== undefined && value > maximum) throw new Error(`${param.name}: at most ${maximum}`);
      args[param.name] = value;
    } else {
      args[param.name] = raw;
    }
  }
  return { type: commandType, args };
}

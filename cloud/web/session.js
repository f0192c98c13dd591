// The robot's live session on the cloud's page (remote wizard of oz): its trees and what
// they do, what happened lately, in the words of the robot's own live view, and its
// buttons. A role that may press (admin, operator, therapist) presses them; the robot
// carries a press out as one on its own buttons page. A viewer sees the board, never
// presses. A press the robot does not take within 2 s is dropped, and the board says so.

const PRESS_OUTCOME = {
  QUEUED: "sent…",
  IN_PROGRESS: "sent…",
  SUCCEEDED: "done by the robot",
  TIMED_OUT: "dropped: the robot did not take it within 2 s (it was not carried out)",
  CANCELED: "canceled",
};

function el(tag, props = {}, ...children) {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children);
  return node;
}

const clockTime = (seconds) => {
  const s = Math.max(0, Math.round(seconds));
  return `${Math.floor(s / 60)}:${String(s % 60).padStart(2, "0")}`;
};

// The words for a press's state (FAILED: the robot's reason).
export function pressOutcome(command) {
  if (command.state === "FAILED") {
    const why = command.result && command.result.error;
    return `not done: ${why || "the robot refused it"}`;
  }
  return PRESS_OUTCOME[command.state] || command.state;
}

// Why nothing can be pressed now ("" when the board is live).
function notLive(session, online) {
  if (session.view.ended) return "The session has ended: the robot stopped. Its last state is shown.";
  if (!online) return "The robot is offline: a press now would be dropped. Its last state is shown.";
  return "";
}

export function renderSession(root, session, { canPress, online, role, onPress, lastPress }) {
  const trees = root.querySelector("#session-trees");
  const happened = root.querySelector("#session-happened");
  const board = root.querySelector("#session-board");
  const none = root.querySelector("#no-session");
  none.hidden = Boolean(session);
  root.querySelector("#session-live").hidden = !session;
  if (!session) return;
  const view = session.view;
  const stale = notLive(session, online);
  root.querySelector("#session-stale").textContent = stale;
  root.querySelector("#session-live").classList.toggle("stale", Boolean(stale));
  const paused = Boolean(view.board && view.board.paused);
  trees.replaceChildren(
    ...view.trees.map((tree) => {
      const idle = paused && tree.tree !== "buttons" ? "paused" : "waiting";
      const doing = tree.doing.length ? tree.doing.join("; ") : tree.status === "RUNNING" ? "" : idle;
      const item = el(
        "li",
        { className: `tree ${tree.status}` },
        el("strong", { textContent: tree.tree }),
        " ",
        el("span", { className: "hint", textContent: doing }),
      );
      item.dataset.tree = tree.tree;
      return item;
    }),
  );
  happened.replaceChildren(
    ...[...view.happened].reverse().map((line) =>
      el(
        "li",
        { className: `tone-${line.tone}` },
        el("span", { className: "age", textContent: clockTime(line.at) }),
        " ",
        el("strong", { textContent: line.who }),
        " ",
        line.what,
      ),
    ),
  );
  root.querySelector("#no-happened").textContent = view.happened_hidden
    ? `What happened is not shown to your role, ${role}: it can quote the child.`
    : "Nothing yet.";
  root.querySelector("#no-happened").hidden = view.happened.length > 0;
  const buttons = view.board;
  root.querySelector("#no-board").hidden = Boolean(buttons);
  board.replaceChildren();
  if (!buttons) return;
  const shown = new Set(buttons.shown);
  for (const button of buttons.buttons) {
    const press = el("button", {
      type: "button",
      className: button.control ? "press control" : "press",
      textContent: button.label,
      disabled: !canPress || Boolean(stale) || !shown.has(button.id),
      title: shown.has(button.id) ? "" : "not shown now",
    });
    press.dataset.button = String(button.id);
    press.addEventListener("click", () => onPress(button));
    board.append(press);
  }
  root.querySelector("#board-role").textContent = canPress
    ? ""
    : `Your role, ${role}, sees the buttons; it does not press them.`;
  const status = [buttons.paused ? "The behaviors are paused." : "", buttons.doing ? `Doing: ${buttons.doing}.` : ""];
  root.querySelector("#board-status").textContent = status.filter(Boolean).join(" ");
  root.querySelector("#press-outcome").textContent = lastPress
    ? `${lastPress.label}: ${pressOutcome(lastPress.command)}`
    : "";
}

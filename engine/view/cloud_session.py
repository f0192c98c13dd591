"""The session as the cloud's page shows it, and the presses that page sends back (remote
wizard of oz: a therapist in the next room).

:class:`CloudSession` reads the consent gate's exit off the robot through a
:class:`~engine.view.hub.ViewHub` of its own, so it knows only what a person's consent
lets leave the robot, told in the live view's own words. Its :meth:`~CloudSession.view`
is what the cloud link pushes: every tree with its status and what its running leaves do
in words, what happened lately, and the button board with the buttons shown now. A press
from the cloud goes to the :class:`~engine.buttons.wizard.Wizard` exactly as a press on
the robot's own buttons page (same queue, same priorities, same safety envelope), credited
to the account that pressed.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from engine.buttons.wizard import Wizard
from engine.services.cloud_push import NO_BOARD
from engine.session.events import NodeStatus, SessionEvent, TreeStarted
from engine.session.sentences import TOLD_KINDS
from engine.view.hub import ViewHub

SHOWN_KINDS = (TreeStarted.kind, NodeStatus.kind, *TOLD_KINDS)
"""What the view is made of: trees, their nodes' statuses, what is told in words (never the
blackboard's changes, which come at every tick)."""
HAPPENED_SENT = 30
"""How many of the latest "what happened" lines the view carries."""


class CloudSession:
    """A reader of the session's exit off the robot (``on_event``, for
    :data:`SHOWN_KINDS`) that keeps the view
    the cloud shows; ``wizard``: the robot's buttons, None when it runs none (the cloud
    link's :class:`~engine.services.cloud_push.SessionShown`)."""

    def __init__(self, hub: ViewHub, wizard: Wizard | None) -> None:
        self.hub = hub
        self.wizard = wizard
        self._sent: dict[str, Any] | None = None
        self.ended = False

    def on_event(self, event: SessionEvent) -> None:
        self.hub.on_event(event)

    def view(self) -> dict[str, Any]:
        """The session now: ``trees`` (name, priority, status, ``doing``: what its running
        leaves do, in words), ``happened`` (the latest lines), ``board`` (None: no buttons),
        ``ended`` (the robot stopped: nothing on the page is current any more)."""
        snapshot = self.hub.snapshot()
        trees = [_tree(tree) for tree in snapshot["trees"]]
        happened = [
            {key: line[key] for key in ("at", "who", "what", "tone")}
            for line in snapshot["happened"][-HAPPENED_SENT:]
        ]
        return {"trees": trees, "happened": happened, "board": self._board(), "ended": self.ended}

    def changed_view(self) -> dict[str, Any] | None:
        """The view when it changed since the last one this returned, else None."""
        view = self.view()
        if view == self._sent:
            return None
        self._sent = view
        return view

    def end(self) -> None:
        """The robot stops: the next view says the session ended."""
        self.ended = True

    def forget_sent(self) -> None:
        """The last view did not reach the cloud: the next look sends the view again."""
        self._sent = None

    def press(
        self, args: dict[str, Any]
    ) -> tuple[str, dict[str, Any], Callable[[], object] | None]:
        """Check a press from the cloud (``{"button": N, "by": account}``): (``SUCCEEDED``,
        the button's label, what queues it for the next step as a local press is) or
        (``FAILED``, why, None)."""
        wizard = self.wizard
        if wizard is None:
            return "FAILED", {"error": NO_BOARD}, None
        number, by = args.get("button"), args.get("by")
        if not isinstance(number, int) or isinstance(number, bool):
            return "FAILED", {"error": f"button: {number!r} is not a button's number"}, None
        button = wizard.board.button(number)
        if button is None:
            count = len(wizard.board.buttons)
            why = f"no button {number} (this board has 0 to {count - 1})"
            return "FAILED", {"error": why}, None
        if number not in wizard.state()["shown"]:  # as the robot's own page refuses it
            return "FAILED", {"error": f"{button.label!r} is not shown now: nothing done"}, None
        return (
            "SUCCEEDED",
            {"pressed": button.label},
            lambda: wizard.press(number, by="cloud", who=str(by or "someone")),
        )

    def _board(self) -> dict[str, Any] | None:
        if self.wizard is None:
            return None
        state = self.wizard.state()
        return {
            "buttons": [button.to_json() for button in self.wizard.board.buttons],
            **state,
        }


def _tree(tree: dict[str, Any]) -> dict[str, Any]:
    """One tree of the hub's snapshot as the cloud shows it."""
    statuses = {status["node"]: status["status"] for status in tree.get("statuses", [])}
    nodes = tree.get("nodes", [])
    root = statuses.get(0, "INVALID")
    leaves = [
        node
        for number, node in enumerate(nodes)
        if statuses.get(node["index"]) == "RUNNING"
        and not (number + 1 < len(nodes) and nodes[number + 1]["depth"] > node["depth"])
    ]
    return {
        "tree": tree["tree"],
        "priority": tree["priority"],
        "status": root,
        "doing": [node["words"] or node["label"] for node in leaves],
    }

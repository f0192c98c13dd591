"""Acting on the simulated vest from the buttons page: a squeeze, a touch, a child's words.

On a simulated vest nobody can squeeze the robot. So a therapist trying a session, or a
trainer showing one, does it on the buttons page. The robot then feels it as it would a
scenario's event at that moment. :class:`ActingNow` takes one event as a scenario file
writes it, without ``at`` (``{"squeeze": {"left_n": 6, "right_n": 6}}``), checks it with
the scenario's own checks, and has the scenario player play it now. The timeline, the
recording and the report tell it as a scenario's event: it is the world's doing, not the
therapist's press.
"""

from __future__ import annotations

from pathlib import Path

from engine.blackboard.catalogue import default_catalogue
from engine.clock import Clock
from engine.files.problems import Mark, Problems
from engine.files.yaml_source import YMap, YScalar, parse_yaml
from engine.hardware.config import RobotConfig
from engine.hardware.touch_pads import name_scenario_pads
from engine.scenario.player import ScenarioPlayer
from engine.scenario.scenario_file import ScenarioEvent, scenario_event
from engine.values.param_problems import CheckContext, did_you_mean

ACTS = ("squeeze", "touch", "hear", "gesture")
"""What a person can do to the simulated vest from the page: no files, faults or commands."""
REQUEST = "the request"
"""How a problem names where it is: ``the request:1:14: ...``."""


class ActingNow:
    """Plays one event a page sends on the simulated vest of ``config``, now."""

    def __init__(self, player: ScenarioPlayer, clock: Clock, config: RobotConfig) -> None:
        self.player = player
        self.clock = clock
        self.config = config
        self._count = 0

    def act(self, text: str) -> ScenarioEvent:
        """Play the event written in ``text`` (JSON, or the YAML of one scenario event
        without ``at``) now; a LoadError with every problem and its place otherwise."""
        document = parse_yaml(text, REQUEST)
        problems = Problems()
        start = Mark(REQUEST, 1, 1)
        if not isinstance(document, YMap) or len(document) != 1:
            problems.add(
                document.mark if document is not None else start,
                "send one thing to do, e.g. {squeeze: {left_n: 6, right_n: 6}}",
                "one of: " + ", ".join(ACTS),
            )
            problems.raise_if_any()
        assert isinstance(document, YMap)
        [(kind, body)] = document.items()
        if kind not in ACTS:
            hint = did_you_mean(kind, list(ACTS)) or "one of: " + ", ".join(ACTS)
            problems.add(document.key_marks[kind], f"the page cannot act {kind!r}", hint)
            problems.raise_if_any()
        if isinstance(body, YMap) and "wav" in body:  # never a file of the robot's disk
            problems.add(body.key_marks["wav"], "from the page, write the words", "hear: hello")
            problems.raise_if_any()
        self._count += 1
        at = YScalar(self.clock.now() - self.player.start_s, start)
        raw = YMap({"at": at, kind: body}, document.mark, {"at": start, **document.key_marks})
        ctx = CheckContext(default_catalogue())
        event = scenario_event(raw, ctx, problems, self._count, Path.cwd())
        said = event.value["text"] if event is not None and kind == "hear" else None
        if said is not None and any(ord(c) < 32 for c in said):
            problems.add(body.mark, "write the child's words, in plain text", "hear: hello")
        if (
            event is not None
            and kind == "squeeze"
            and not (event.value["left_n"] or event.value["right_n"])
        ):
            problems.add(body.mark, "a squeeze needs a force on one side at least", "left_n: 6")
        if event is not None:
            problems.extend(name_scenario_pads([event], self.config))
        problems.raise_if_any()
        assert event is not None
        self.player.add(event)
        return event

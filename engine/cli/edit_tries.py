"""What `vest edit` runs beside the page, each in a process of its own (a tree that hangs
or fails cannot take the editor with it): a tree as it is on the page tried on the
simulated vest with one event (a pat, a squeeze, words said, a wave), on a virtual clock
for its timeline or in real time under the live view to watch it; and a dialog's phrases
said and heard as the robot hears them."""

from __future__ import annotations

import contextlib
import json
import shutil
import subprocess
import sys
import tempfile
import threading
from pathlib import Path
from typing import IO

import yaml

from engine.errors import ConfigError
from engine.files.yaml_source import plain, resolved
from engine.loader.substitution import load_profile
from engine.session.codec import decode
from engine.session.sentences import event_line

TRY_AT_S = 1.0
TRY_FOR_S = 8.0
"""A try: the event at 1 s, the tree watched until 8 s (a cooldown's rest, a slow arm)."""
TRY_TIMEOUT_S = 60.0
WATCH_AT_S = 5.0
WATCH_FOR_S = 30.0
"""Watched live: the event 5 s after the press (time to open the view), 30 s in all."""
MAX_SAID = 200
VEST = "import sys; from engine.cli import main; sys.exit(main())"
STOP_WAIT_S = 10.0


class TryError(ValueError):
    """A try the page asked for that cannot be made, in words."""


MAX_TIMES = 5
LENGTH_S = {"pat": (0.3, 0.1, 10.0), "squeeze": (2.0, 0.1, 10.0)}
"""How long a pat and a squeeze last by default, and the least and most a try may ask."""
STRENGTH_N = (6.0, 0.5, 50.0)
APART_S = (1.5, 0.2, 10.0)
SIDES = ("both", "left", "right")
"""Which side pads a tried squeeze presses."""


def tried_events(asked: object, pads: list[str], at_s: float = TRY_AT_S) -> list[dict[str, object]]:
    """The scenario events the page asked for, from ``at_s`` on: ``{"kind": "pat", "pad":
    ...}``, ``{"kind": "squeeze", "strength_n": ...}``, ``{"kind": "say", "text": ...}`` or
    ``{"kind": "wave"}``, each with ``seconds`` (how long a pat or squeeze lasts),
    ``times`` (1 to 5) and ``apart_s`` (seconds from one start to the next); a squeeze's
    ``side`` is ``both`` (a hug, the default), ``left`` or ``right``."""
    if not isinstance(asked, dict):
        raise TryError("event: a pat, a squeeze, a phrase said or a wave")
    kind = asked.get("kind")
    times = _number(asked, "times", (1, 1, MAX_TIMES), whole=True)
    lasts_s = LENGTH_S.get(str(kind), (0.0, 0.0, 0.0))[0]
    if isinstance(asked.get("seconds"), int | float) and not isinstance(asked["seconds"], bool):
        lasts_s = float(asked["seconds"])
    default_apart_s = max(APART_S[0], lasts_s + 1.0)  # each one over before the next
    apart_s = _number(asked, "apart_s", (default_apart_s, *APART_S[1:]))
    if times > 1 and apart_s <= lasts_s:
        raise TryError(
            f"apart_s: {apart_s:g} s apart, each lasting {lasts_s:g} s, they would be one long "
            f"{'squeeze' if kind == 'squeeze' else 'touch'}: set Apart to more than How long "
            f"(empty: {default_apart_s:g} s)"
        )
    if kind == "pat":
        pad = asked.get("pad")
        if pad not in pads:
            raise TryError(f"no pad {pad!r} on this robot (pads: {', '.join(pads)})")
        one: dict[str, object] = {
            "touch": {"pad": pad, "seconds": _number(asked, "seconds", LENGTH_S["pat"])}
        }
    elif kind == "squeeze":
        strength = _number(asked, "strength_n", STRENGTH_N)
        seconds = _number(asked, "seconds", LENGTH_S["squeeze"])
        side = asked.get("side") or "both"
        if side not in SIDES:
            raise TryError(f"side: {str(side)[:20]!r} is not one of {', '.join(SIDES)}")
        left, right = (strength if side in (s, "both") else 0.0 for s in ("left", "right"))
        one = {"squeeze": {"left_n": left, "right_n": right, "seconds": seconds}}
    elif kind == "say":
        said = asked.get("text")
        if not isinstance(said, str) or not said.strip() or len(said) > MAX_SAID:
            raise TryError(f"say: the words a person says, 1 to {MAX_SAID} characters")
        one = {"hear": {"text": said.strip()}}
    elif kind == "wave":
        one = {"gesture": "wave"}
    else:
        raise TryError("event: a pat, a squeeze, a phrase said or a wave")
    return [{"at": round(at_s + n * apart_s, 3), **one} for n in range(int(times))]


def _number(
    asked: dict[str, object], name: str, allowed: tuple[float, float, float], *, whole: bool = False
) -> float:
    """``asked[name]`` (its default when not given) if it is a number in range; TryError
    naming it otherwise."""
    default, least, most = allowed
    value = asked.get(name, default)
    if value is None or value == "":
        value = default
    if isinstance(value, bool) or not isinstance(value, int | float) or (whole and value % 1):
        raise TryError(f"{name}: a {'whole ' if whole else ''}number from {least:g} to {most:g}")
    if not least <= value <= most:  # exact for a huge whole number too
        shown = f"{value:g}" if isinstance(value, float) else str(value)[:20]
        raise TryError(f"{name}: {shown} is not from {least:g} to {most:g}")
    return float(value)


class TryOnSimulatedVest:
    """Runs a tree being edited on the simulated vest, on a virtual clock, with one event:
    ``vest run --fast --speech text`` in a process of its own (a tree that hangs or fails
    cannot take the editor with it), on a copy of the folder's trees (its subtrees), the
    folder's dialogs and ``hardware``. Its timeline, in sentences, is the answer."""

    def __init__(self, folder: Path, hardware: Path | None, pads: list[str]) -> None:
        self.folder, self.hardware, self.pads = folder, hardware, pads
        self._one_at_a_time = threading.Lock()  # each try is a whole vest run
        self._watching: tuple[subprocess.Popen[str], Path] | None = None

    def __call__(self, name: str, text: str, asked: object) -> list[str]:
        """The timeline of ``text`` (the file ``name``) tried with the event ``asked`` (as
        the profile ``asked["profile"]`` sets the trees, when it names one); TryError (a
        ValueError) for an event that cannot be or a run that failed."""
        events = tried_events(asked, self.pads)
        profile = self._profile(asked)
        if not self._one_at_a_time.acquire(blocking=False):
            raise TryError("another try is running: wait for its answer")
        try:
            return self._tried(name, text, events, profile)
        finally:
            self._one_at_a_time.release()

    def _profile(self, asked: object) -> str | None:
        """The profile a try asks for (a file of trees/profiles/ by its name), or None."""
        wanted = asked.get("profile") if isinstance(asked, dict) else None
        if wanted in (None, ""):
            return None
        folder = self.folder / "trees" / "profiles"
        names = sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []
        if wanted not in names:
            known = ", ".join(names) or "none"
            raise TryError(f"profile: no profile {str(wanted)[:40]!r} (profiles: {known})")
        return str(wanted)

    def _tried(
        self, name: str, text: str, events: list[dict[str, object]], profile: str | None
    ) -> list[str]:
        with tempfile.TemporaryDirectory(prefix="vest-try-") as scratch:
            last_s = max(float(str(event["at"])) for event in events)
            command = self._command(Path(scratch), name, text, events, last_s + TRY_FOR_S)
            if profile is not None:
                command += ["--profile", profile]
            try:
                done = subprocess.run(
                    [*command, "--fast", "--json"],
                    capture_output=True,
                    text=True,
                    timeout=TRY_TIMEOUT_S,
                    check=False,
                )
            except subprocess.TimeoutExpired:
                raise TryError(f"the try ran over {TRY_TIMEOUT_S:g} s and was stopped") from None
        if done.returncode != 0:
            said = done.stderr.strip().splitlines()
            raise TryError(said[-1] if said else f"vest run ended with {done.returncode}")
        told = (_sentence(line) for line in done.stdout.splitlines() if line.strip())
        lines = [sentence for sentence in told if sentence is not None]
        tree = _tree_name(name, text)
        settings = self._settings_in_use(text, profile)
        if not any(f" s {tree}: " in line for line in lines):
            lines.append(
                f"{tree} did nothing: what it waits for did not happen (look at its first "
                "question: the pad, the threshold, the words) or another tree had its turn"
                + (f"; {settings}" if settings else "")
            )
        elif settings:  # what it answered with, to compare with another profile's try
            lines.append(f"{tree} answered; {settings}")
        return lines

    def _settings_in_use(self, text: str, profile: str | None) -> str:
        """``its settings in this try: hug_threshold_n 2.5 (profile child)``: the tree's
        numeric ``params:`` as the try set them (empty when it has none)."""
        try:
            document = yaml.safe_load(text)
        except yaml.YAMLError:
            return ""
        declared = document.get("params") if isinstance(document, dict) else None
        if not isinstance(declared, dict):
            return ""
        chosen: dict[str, object] = {}
        if profile is not None:
            path = self.folder / "trees" / "profiles" / f"{profile}.yaml"
            with contextlib.suppress(ConfigError):
                given = load_profile(path).params
                chosen = {name: plain(value.value) for name, value in given.items()}
        told = [  # the numbers: thresholds and times, what decides whether it acts
            f"{name} {chosen[name]} (profile {profile})" if name in chosen else f"{name} {value}"
            for name, value in declared.items()
            if isinstance(chosen.get(name, value), int | float)
            and not isinstance(chosen.get(name, value), bool)
        ]
        return "its settings in this try: " + ", ".join(told) if told else ""

    def watch(self, name: str, text: str, asked: object, host: str) -> str:
        """Run ``text`` in real time with the event ``asked`` at :data:`WATCH_AT_S` under
        the live view (on ``host``, as the editor): the view's address. The run before
        is stopped; TryError when it cannot start."""
        events = tried_events(asked, self.pads, WATCH_AT_S)
        profile = self._profile(asked)
        with self._one_at_a_time:
            self.stop_watching()
            scratch = Path(tempfile.mkdtemp(prefix="vest-watch-"))
            command = self._command(scratch, name, text, events, WATCH_FOR_S)
            command += ["--profile", profile] if profile is not None else []
            command += ["--view", "--view-port", "0", "--view-host", host]
            process = subprocess.Popen(
                command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
            )
            self._watching = (process, scratch)
            assert process.stderr is not None
            said: list[str] = []
            for line in process.stderr:  # it prints the view's address once it serves
                if line.startswith("view: "):
                    _drain(process.stderr)
                    return line.removeprefix("view: ").strip()
                said.append(line.strip())
            self.stop_watching()
            raise TryError(said[-1] if said else "vest run ended before its view started")

    def stop_watching(self) -> None:
        """End the watched run, if one is going on, and remove its copy of the folder."""
        if self._watching is None:
            return
        process, scratch = self._watching
        self._watching = None
        process.terminate()
        try:
            process.wait(timeout=STOP_WAIT_S)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
        shutil.rmtree(scratch, ignore_errors=True)

    def _command(
        self, scratch: Path, name: str, text: str, events: list[dict[str, object]], seconds: float
    ) -> list[str]:
        """``vest run`` of ``text`` (the file ``name``) among the folder's other trees, in a
        copy of the folder's trees and dialogs in ``scratch`` (a link leading out of the
        folder is not followed), on a scenario of ``seconds`` with ``events`` and the robot
        config."""
        copy = scratch / "folder"
        for part in ("trees", "dialogs"):
            _copy_inside(self.folder / part, copy / part, resolved(self.folder))
        tried = copy / name
        tried.parent.mkdir(parents=True, exist_ok=True)
        tried.write_text(text, encoding="utf-8")
        scenario = scratch / "try.yaml"
        scenario.write_text(
            yaml.safe_dump({"duration_s": seconds, "events": events}), encoding="utf-8"
        )
        command = [sys.executable, "-c", VEST, "run", "--speech", "text"]
        among = copy / "trees" if tried.is_relative_to(copy / "trees") else tried
        command += ["--trees", str(among), "--scenario", str(scenario)]
        if (copy / "dialogs").is_dir():
            command += ["--dialogs", str(copy / "dialogs")]
        if self.hardware is not None:
            command += ["--hardware", str(self.hardware)]
        return command


def _copy_inside(source: Path, to: Path, inside: Path) -> None:
    """``source``'s files into ``to``, but those that lead out of ``inside`` (links)."""
    if not source.is_dir():
        return
    shutil.copytree(
        source,
        to,
        ignore=lambda at, names: [
            name for name in names if not resolved(Path(at) / name).is_relative_to(inside)
        ],
    )


def _drain(stream: IO[str]) -> None:
    """Read what else ``stream`` says, in a thread, so the run never blocks on a full pipe."""
    threading.Thread(target=lambda: [None for _ in stream], name="watch-drain", daemon=True).start()


def _tree_name(name: str, text: str) -> str:
    """The tree's name as its file gives it (the file's stem when it gives none)."""
    try:
        document = yaml.safe_load(text)
    except yaml.YAMLError:
        document = None
    given = document.get("name") if isinstance(document, dict) else None
    return str(given) if given else Path(name).stem


def _sentence(line: str) -> str | None:
    """A ``--json`` line of the run as ``"1.00 s tickles: says ..."``: the event read back
    (:mod:`engine.session.codec`) and told as the timeline tells it (None: the timeline
    has no line for it, as a refusal the action's outcome tells)."""
    message = json.loads(line)
    event = decode({**message, "kind": message.pop("event")})
    told = event_line(event)
    return None if told is None else f"{event.t_s:.2f} s {told[0]}: {told[1]}"


HEAR_TIMEOUT_S = 300.0


class HearCheck:
    """`vest dialogs check --quick` on a dialog as it is on the page: each phrase said once
    by the robot's neural voice and heard as the robot hears (a process of its own, about
    20 s for the shipped dialogs). Its lines are the answer, the file named as the page
    names it."""

    def __call__(self, name: str, text: str) -> list[str]:
        with tempfile.TemporaryDirectory(prefix="vest-hear-") as scratch:
            checked = Path(scratch) / Path(name).name
            checked.write_text(text, encoding="utf-8")
            command = [sys.executable, "-c", VEST, "dialogs", "check", "--quick", str(checked)]
            try:
                done = subprocess.run(
                    command, capture_output=True, text=True, timeout=HEAR_TIMEOUT_S, check=False
                )
            except subprocess.TimeoutExpired:
                raise TryError(f"the check ran over {HEAR_TIMEOUT_S:g} s and was stopped") from None
            said = (done.stdout + done.stderr).replace(str(checked), name)
        if done.returncode not in (0, 1):  # 1: it found problems, which are the answer
            lines = said.strip().splitlines()
            raise TryError(lines[-1] if lines else f"the check ended with {done.returncode}")
        return [line for line in said.splitlines() if line.strip()]

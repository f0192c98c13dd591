"""Check dialogs before a session: will each phrase be understood, and as its own rule?

vest dialogs check [DIR or FILE] first matches every phrase's text (a phrase another rule
takes, or none, is a mistake in the file), then speaks every phrase with the robot's
voices at several speeds, with noise, runs it through the recognizer and the matcher,
and reports what is not recognized and which rules get confused. Exits 1 when anything
is reported. --quick speaks each phrase once (the joe voice, natural speed, no noise).
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from engine.blackboard.catalogue import default_catalogue
from engine.cli.output import shown
from engine.cli.run_inputs import dialogs_folder
from engine.dialogs.library import DialogLibrary, load_dialog
from engine.dialogs.model import Dialog, DialogRule, FollowUp
from engine.errors import ConfigError
from engine.speech.hearing import hear, spoken
from engine.speech.recognizer import WhisperRecognizer
from engine.speech.vad import SileroVad
from engine.speech.voice_models import load_voice
from engine.speech.voices import Voice, steady_voice


@dataclass(frozen=True)
class Variant:
    """One way of saying a phrase: a voice, a speed, and noise (dB SNR, None: clean)."""

    voice: str
    speed: float
    snr_db: float | None

    def __str__(self) -> str:
        noise = f", {self.snr_db:g} dB SNR" if self.snr_db is not None else ""
        return f"{self.voice} x{self.speed:g}{noise}"


VARIANTS = (
    Variant("joe", 1.0, None),
    Variant("joe", 1.25, 10.0),
    Variant("espeak", 0.85, 20.0),
    Variant("espeak", 1.15, None),
)
QUICK = (Variant("joe", 1.0, None),)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    actions = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    check = actions.add_parser(
        "check", help="check every phrase of every dialog", description=__doc__
    )
    check.add_argument(
        "folder",
        type=Path,
        nargs="?",
        default=None,
        help="a dialogs folder or file (default: dialogs/)",
    )
    check.add_argument("--quick", action="store_true", help="one voice, natural speed, no noise")


def _in_context(dialog: Dialog) -> list[tuple[DialogRule, FollowUp | None]]:
    """Every rule with the follow-up it is heard in (None: the dialog's own rules)."""
    found: list[tuple[DialogRule, FollowUp | None]] = []
    pending: list[tuple[DialogRule, FollowUp | None]] = [(r, None) for r in dialog.rules]
    while pending:
        rule, context = pending.pop(0)
        found.append((rule, context))
        if rule.follow_up is not None:
            pending.extend((r, rule.follow_up) for r in rule.follow_up.rules)
    return found


def _library(given: Path | None) -> DialogLibrary:
    """The dialogs of a folder (default dialogs/) or of one file; ConfigError when there
    are none."""
    catalogue = default_catalogue()
    if given is not None and given.is_file():
        dialog = load_dialog(given, catalogue)
        return DialogLibrary({dialog.name: dialog})
    if given is not None and not given.is_dir():
        raise ConfigError(f"{given}: no such folder or file")
    folder = dialogs_folder(given)
    if folder is None:
        raise ConfigError("no dialogs/ folder here; name one: vest dialogs check DIR")
    library = DialogLibrary.from_folder(folder, catalogue)
    if not library.names:
        raise ConfigError(f"{folder}: no dialog files (*.yaml) in it")
    return library


def _where(dialog: Dialog, rule: DialogRule) -> str:
    return f"{shown(dialog.source)}:{rule.line}: rule {rule.id!r}"


def main(args: argparse.Namespace) -> int:
    library = _library(args.folder)  # LoadError: exit 1
    reported = 0
    written_wrong: set[tuple[str, str]] = set()
    for name in library.names:
        dialog = library.dialogs[name]
        for rule, context in _in_context(dialog):
            for phrase in rule.phrases:
                verdict = dialog.judge(phrase.text, context)
                if verdict.match is None or verdict.match.rule.id != rule.id:
                    got = f"rule {verdict.match.rule.id!r}" if verdict.match else verdict.reason
                    print(f"{_where(dialog, rule)}: phrase {phrase.text!r} as written -> {got}")
                    reported += 1
                    written_wrong.add((rule.id, phrase.text))
    variants = QUICK if args.quick else VARIANTS
    voices: dict[str, Voice] = {}
    for variant in variants:
        voice = load_voice(variant.voice)
        voices[variant.voice] = steady_voice(voice)
    recognizer = WhisperRecognizer()
    recognizer.listen_for(library.phrases())
    vad = SileroVad()
    tried = 0
    progress = sys.stderr.isatty()
    confused: Counter[tuple[str, str]] = Counter()
    for name in library.names:
        dialog = library.dialogs[name]
        for rule, context in _in_context(dialog):
            for phrase in rule.phrases:
                if (rule.id, phrase.text) in written_wrong:
                    continue  # already reported: speaking it cannot help
                for variant in variants:
                    tried += 1
                    if progress:
                        print(f"\r{tried} spoken", end="", file=sys.stderr, flush=True)
                    audio = spoken(
                        voices[variant.voice], phrase.text, variant.speed, variant.snr_db
                    )
                    hearing = hear(audio, vad, recognizer, dialog, context)
                    match = hearing.verdict.match if hearing.verdict is not None else None
                    if match is not None and match.rule.id == rule.id:
                        continue
                    reported += 1
                    if match is not None:
                        confused[(rule.id, match.rule.id)] += 1
                    why = (
                        f"rule {match.rule.id!r}"
                        if match is not None
                        else hearing.verdict.reason
                        if hearing.verdict is not None
                        else "no speech found"
                    )
                    print(
                        f"{_where(dialog, rule)}: {phrase.text!r} ({variant}) heard as "
                        f"{hearing.heard!r} -> {why}"
                    )
    if progress:
        print("\r", end="", file=sys.stderr)
    for (said, taken), count in confused.most_common():
        print(f"confused: rule {said!r} heard as rule {taken!r} {count} time(s)")
    print(f"{tried} phrase recordings ({len(variants)} per phrase): {reported} problem(s)")
    return 1 if reported else 0

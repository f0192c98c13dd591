"""Check dialogs before a session: will each phrase be understood, and as its own rule?

vest dialogs check [DIR or FILE] first matches every phrase's text (a phrase another rule
takes, or none, is a mistake in the file), then speaks every phrase as people would say
it (two neural voices: hibari, clean, and joe, faster, in 10 dB of noise), hears it as
the robot does (voice activity, its recognizer, the matcher) and reports:
- a problem: a phrase heard as another rule (the robot would answer the wrong question),
  or one not understood even when said clearly;
- a note: a phrase understood when said clearly but missed in noise (the robot says it
  did not understand, and the person says it again): worth a look, not a mistake.
Exits 1 when there is a problem. --quick says each phrase once (hibari, clean).
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
from engine.dialogs.model import Dialog, DialogRule
from engine.errors import ConfigError
from engine.speech.hearing import hear, spoken
from engine.speech.phrase_search import PhraseGrammar
from engine.speech.recognizers import default_recognizer
from engine.speech.settings import HEARING_NAMES, RECOGNIZER_NAMES
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


VARIANTS = (Variant("hibari", 1.0, None), Variant("joe", 1.15, 10.0))
"""The clear way first. espeak-ng's formant voice is left out: it is no person's voice,
and what the recognizers miss in it (most of what this check once reported) says
nothing about a dialog."""
QUICK = VARIANTS[:1]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    actions = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    check = actions.add_parser(
        "check",
        help="check every phrase of every dialog",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,  # the docstring's own lines
    )
    check.add_argument(
        "folder",
        type=Path,
        nargs="?",
        default=None,
        help="a dialogs folder or file (default: dialogs/)",
    )
    check.add_argument("--quick", action="store_true", help="one voice, natural speed, no noise")
    check.add_argument(
        "--recognizer",
        choices=RECOGNIZER_NAMES,
        default=None,
        help="moonshine (the robot's default) or whisper",
    )
    check.add_argument(
        "--hearing",
        choices=HEARING_NAMES,
        default="adults",
        help="hear as for adults (the default) or children: as the profile's hearing:",
    )


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
        for rule, context in dialog.rules_in_context():
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
    children = args.hearing == "children"
    recognizer, instead = default_recognizer(args.recognizer, children=children)
    if instead:
        print(f"vest dialogs check: {instead}", file=sys.stderr)
    phrases = library.phrases()
    recognizer.listen_for(phrases)
    whole_turn = PhraseGrammar(phrases).is_a_whole_turn
    vad = SileroVad()
    tried = notes = 0
    progress = sys.stderr.isatty()
    confused: Counter[tuple[str, str]] = Counter()
    for name in library.names:
        dialog = library.dialogs[name]
        for rule, context in dialog.rules_in_context():
            for phrase in rule.phrases:
                if (rule.id, phrase.text) in written_wrong:
                    continue  # already reported: speaking it cannot help
                for index, variant in enumerate(variants):
                    tried += 1
                    if progress:
                        print(f"\r{tried} spoken", end="", file=sys.stderr, flush=True)
                    audio = spoken(
                        voices[variant.voice], phrase.text, variant.speed, variant.snr_db
                    )
                    hearing = hear(
                        audio, vad, recognizer, dialog, context, whole_turn, children=children
                    )
                    match = hearing.verdict.match if hearing.verdict is not None else None
                    if match is not None and match.rule.id == rule.id:
                        continue
                    problem = match is not None or index == 0
                    if match is not None:
                        confused[(rule.id, match.rule.id)] += 1
                    why = (
                        f"rule {match.rule.id!r}"
                        if match is not None
                        else hearing.verdict.reason
                        if hearing.verdict is not None
                        else "no speech found"
                    )
                    heard = repr(hearing.heard) if hearing.heard is not None else "nothing"
                    kind = "" if problem else "note: "
                    print(
                        f"{_where(dialog, rule)}: {kind}{phrase.text!r} ({variant}) heard as "
                        f"{heard} -> {why}"
                    )
                    reported += problem
                    notes += not problem
    if progress:
        print("\r", end="", file=sys.stderr)
    for (said, taken), count in confused.most_common():
        print(f"confused: rule {said!r} heard as rule {taken!r} {count} time(s)")
    print(
        f"{tried} phrase recordings ({len(variants)} per phrase): {reported} problem(s), "
        f"{notes} note(s)"
    )
    return 1 if reported else 0

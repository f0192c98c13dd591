"""Run the robot's hearing on recordings: voice activity, recognition, the dialog's rule.

For each WAV file: what was heard, which rule of the dialog matched and its score, and
the answer (or the fallback; [name] is a value the robot fills in from its sensors). A
recording with several utterances is heard as a conversation: one line each, and an
answer that asks a question (then:, or a confirm: question) hears the next utterance as
its reply. --json prints one object per utterance (per file, for a file of one question):
{"file": ..., "heard": text or null, "rule": rule id or null, "score": ..., "answer": ...,
"asks": the rule whose confirm: question the answer is, or null, "latency_s": ...}.
"heard" in lower case, without punctuation, is a phrase of the dialog that the robot found
in the sound where the recognizer's own words held none. latency_s is the seconds from the
end of speech (its last voiced frame) to the intent, as the robot would live on this
machine: it recognizes the speech so far during its wait for silence (0.3 s, or 0.2 s
after a whole phrase, counted in 32 ms frames; 0.8 s for --hearing children), so this is
the wait or the recognition, whichever ends later (measured here). A file is heard whole:
the live robot does not hear speech while it answers.
--mic listens on the microphone instead (the robot config's, or --device) until Ctrl-C.
--echo-of PLAYED.wav measures how the robot hears its own voice in FILE.wav (recorded while
its speaker played PLAYED.wav): the echo path, and whether it would stop for it.
--text "do you like dogs" hears a typed phrase as the robot would hear it spoken: said by
the robot's voice (hibari, natural speed), then through the same hearing (its "file" is the
text, quoted).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from engine.blackboard.catalogue import default_catalogue
from engine.cli.output import shown
from engine.cli.run_inputs import dialogs_folder
from engine.clock import RealClock
from engine.dialogs.library import DialogLibrary
from engine.dialogs.model import Dialog
from engine.errors import ConfigError, UsageError
from engine.media.audio import read_wav
from engine.speech.hearing import Hearing, conversation, spoken
from engine.speech.phrase_search import PhraseGrammar
from engine.speech.recognizers import default_recognizer
from engine.speech.settings import HEARING_NAMES, RECOGNIZER_NAMES
from engine.speech.voice_models import DEFAULT_VOICE, load_voice
from engine.speech.voices import steady_voice

MAX_TYPED_CHARS = 400
"""The longest typed phrase (a sentence or two)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("files", type=Path, nargs="*", metavar="FILE.wav", help="recordings")
    parser.add_argument("--mic", action="store_true", help="listen on the microphone")
    parser.add_argument(
        "--text",
        action="append",
        default=[],
        metavar="PHRASE",
        help="hear a typed phrase, spoken by the robot's voice (e.g. --text \"do you like "
        'dogs"); may be given several times',
    )
    parser.add_argument(
        "--recognizer",
        choices=RECOGNIZER_NAMES,
        default=None,
        help="moonshine (the default) or whisper",
    )
    parser.add_argument(
        "--hearing",
        choices=HEARING_NAMES,
        default="adults",
        help="hear adults (the default) or children (longer pauses, phrases as children "
        "say them), as a profile's 'hearing:' does",
    )
    parser.add_argument(
        "--device", default=None, help="ALSA capture device for --mic (default: the config's)"
    )
    parser.add_argument(
        "--hardware",
        type=Path,
        default=None,
        metavar="CONFIG",
        help="robot config naming the microphone (for --mic; default: the ALSA default)",
    )
    parser.add_argument(
        "--dialogs", type=Path, default=None, help="dialogs folder (default: dialogs/)"
    )
    parser.add_argument(
        "--dialog", default="default", help="which dialog answers (default: default)"
    )
    parser.add_argument("--json", action="store_true", help="one JSON object per utterance")
    parser.add_argument(
        "--echo-of",
        type=Path,
        default=None,
        metavar="PLAYED.wav",
        help="FILE.wav was recorded on the robot's microphone while its speaker played "
        "PLAYED.wav: measure the echo path (a scenario's echo: event) and say whether the "
        "robot would stop for its own voice (exit 1 when it would)",
    )


def load_dialog_named(folder: Path | None, name: str) -> tuple[DialogLibrary, Dialog]:
    """The dialogs of ``folder`` and the one called ``name``; ConfigError when missing."""
    found = dialogs_folder(folder)
    if found is None:
        raise ConfigError("no dialogs/ folder here; give one with --dialogs DIR")
    library = DialogLibrary.from_folder(found, default_catalogue())
    dialog = library.get(name)
    if dialog is None:
        have = ", ".join(library.names) or "none: no dialog files (*.yaml) in it"
        raise ConfigError(f"no dialog {name!r} in {found}; dialogs: {have}")
    return library, dialog


def describe(name: str, hearing: Hearing) -> str:
    if hearing.heard is None:
        return f"{name}: heard nothing"
    line = f"{name}: heard {hearing.heard!r}"
    verdict = hearing.verdict
    if verdict is not None and verdict.match is not None:
        line += f" -> rule {verdict.match.rule.id!r} ({verdict.match.score:.2f})"
    elif verdict is not None:
        line += f" -> no rule ({verdict.reason})"
    if hearing.asks is not None:
        line += f" -> asks whether it heard rule {hearing.asks.id!r}: {hearing.answer!r}"
    elif hearing.answer is not None:
        line += f" -> says {hearing.answer!r}"
    return line


def main(args: argparse.Namespace) -> int:
    if args.echo_of is not None:
        if len(args.files) != 1 or args.mic or args.text:
            raise UsageError("--echo-of PLAYED.wav goes with one FILE.wav (the microphone's)")
        from engine.cli.hear_echo import hear_own_voice

        microphone, speaker = read_wav(args.files[0]), read_wav(args.echo_of)
        names = str(args.files[0]), str(args.echo_of)
        return hear_own_voice(microphone, speaker, *names, as_json=args.json)
    if args.mic and (args.files or args.text):
        raise UsageError("give WAV files or --text, or --mic, not both")
    if not args.mic and not args.files and not args.text:
        raise UsageError(
            'give WAV files to hear, --text "a phrase", or --mic to listen on the microphone'
        )
    for phrase in args.text:
        if not phrase.strip() or len(phrase) > MAX_TYPED_CHARS:
            raise UsageError(
                f"--text {phrase[:40]!r}: a phrase of 1 to {MAX_TYPED_CHARS} characters"
            )
    library, dialog = load_dialog_named(args.dialogs, args.dialog)
    audio = [(str(path), read_wav(path)) for path in args.files]  # read before any work
    if args.text:
        voice = load_voice(DEFAULT_VOICE)
        steady = steady_voice(voice)
        audio += [(repr(phrase), spoken(steady, phrase)) for phrase in args.text]
    from engine.speech.vad import SileroVad

    children = args.hearing == "children"
    recognizer, instead = default_recognizer(args.recognizer, children=children)
    if instead:
        print(f"vest hear: {instead}", file=sys.stderr)
    phrases = library.phrases()
    recognizer.listen_for(phrases)
    whole_turn = PhraseGrammar(phrases).is_a_whole_turn
    vad = SileroVad()
    if args.mic:
        from engine.cli.hear_live import listen_live

        return listen_live(args, recognizer, dialog, RealClock(), whole_turn)
    for name, recording in audio:
        heard = conversation(recording, vad, recognizer, dialog, whole_turn, children=children)
        for hearing in heard:
            if args.json:
                print(json.dumps(hearing.as_json(name), ensure_ascii=False))
            else:
                print(describe(shown(name), hearing))
    return 0

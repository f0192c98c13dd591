"""Children's voices for bench/bench_speech.py (issue 38): how the robot hears children it
was never tuned on, by age band, with adults' hearing and with children's.

The clips: ../shared/data/children-speech (speechocean762, Zhang et al., Interspeech 2021,
Apache-2.0: Mandarin-speaking children aged 6 to 12 reading English sentences; every clip a
different sentence). :data:`HELD_BACK_SEED` chooses 4 children of each age band whom no
setting of the children's hearing was ever tried on; the other 20 are the tuning children.
The figures that count are the held-back children's.

- *In the dialog*: a dialog holding every sentence of the corpus (560 phrases, far more
  alike than a therapist's dialog) hears each held-back clip as the robot would (Silero on
  the stream, drafts, the default recognizer and its second opinion, the matcher): right,
  wrong, "sorry"; and end of speech to intent (p50, p90).
- *Out of the dialog*: a dialog of the tuning children's sentences only hears the held-back
  clips, none of which it holds: every answer is wrong.
- *Adults out of the dialog*: the 43 recordings of people (tests/speech/real_voices.py)
  heard with children's hearing against dialogs/default.yaml, which means none of them.

Targets: never wrong; at least 60 % right at 6-8 and 80 % at 9-12; end of speech to
intent p90 within 0.5 s.
"""

from __future__ import annotations

import json
import random
import statistics
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from engine.blackboard.catalogue import default_catalogue
from engine.dialogs.library import load_dialog
from engine.dialogs.model import Dialog
from engine.media.audio import Audio, read_wav
from engine.speech.hearing import heard_live
from engine.speech.phrase_search import PhraseGrammar
from engine.speech.recognizer import Recognizer
from engine.speech.vad import SileroVad

ROOT = Path(__file__).resolve().parents[1]
CORPUS = ROOT.parent / "shared" / "data" / "children-speech"
HELD_BACK_SEED = 38
"""random.Random(38) picks the held-back children: 4 of the 6-8-year-olds, then 4 of the
9-12-year-olds, from each band's speakers in order."""
HELD_PER_BAND = 4


@dataclass(frozen=True)
class ChildClip:
    text: str
    speaker: str
    age: int
    audio: Audio

    @property
    def band(self) -> str:
        return "6-8" if self.age <= 8 else "9-12"


@dataclass
class BandTally:
    """How one hearing fared on one age band."""

    right: int = 0
    wrong: int = 0
    sorry: int = 0
    latencies: list[float] = field(default_factory=list)  # of every clip heard
    answered: list[float] = field(default_factory=list)  # of those a rule answered
    mistakes: list[str] = field(default_factory=list)

    @property
    def clips(self) -> int:
        return self.right + self.wrong + self.sorry


def split_corpus(corpus: Path = CORPUS) -> tuple[list[ChildClip], list[ChildClip]]:
    """The tuning children's clips and the held-back children's, each in the index's order."""
    index = json.loads((corpus / "index.json").read_text(encoding="utf-8"))
    young = sorted({c["speaker"] for c in index if c["age"] <= 8})
    old = sorted({c["speaker"] for c in index if c["age"] >= 9})
    choose = random.Random(HELD_BACK_SEED)
    held = set(choose.sample(young, HELD_PER_BAND) + choose.sample(old, HELD_PER_BAND))
    tuning: list[ChildClip] = []
    held_back: list[ChildClip] = []
    for entry in index:
        clip = ChildClip(
            entry["text"], entry["speaker"], entry["age"], read_wav(corpus / entry["file"])
        )
        (held_back if clip.speaker in held else tuning).append(clip)
    return tuning, held_back


def sentences_dialog(texts: list[str]) -> Dialog:
    """A dialog with one rule a sentence, its id the sentence's words joined by ``_``,
    and a "sorry"."""
    rules = [{"id": rule_id(text), "hear": [text], "say": "ok"} for text in texts]
    document = {"dialog": "sentences", "rules": rules, "fallback": "Sorry?"}
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "sentences.yaml"
        path.write_text(yaml.safe_dump(document), encoding="utf-8")
        return load_dialog(path, default_catalogue())


def rule_id(text: str) -> str:
    return "_".join(text.split())


def hear_children(
    clips: list[ChildClip],
    dialog: Dialog,
    recognizer: Recognizer,
    vad: SileroVad,
    *,
    children: bool,
) -> dict[str, BandTally]:
    """Each clip heard live and judged by ``dialog``: a clip is right when the rule holding
    its sentence answers, wrong when another rule does (any rule, where the dialog does not
    hold it), sorry when none does. Latency: the last utterance's end of speech to its text
    (for a sorry, the robot's whole wait for silence and any second opinion)."""
    recognizer.listen_for(dialog.phrases)
    whole_turn = PhraseGrammar(dialog.phrases).is_a_whole_turn
    tallies: dict[str, BandTally] = {}
    for clip in clips:
        parts = heard_live(clip.audio, vad, recognizer, whole_turn, children=children)
        heard = " ".join(part.text for part in parts if part.text)
        verdict = dialog.judge(heard) if heard else None
        got = verdict.match.rule.id if verdict is not None and verdict.match else None
        tally = tallies.setdefault(clip.band, BandTally())
        if parts:
            tally.latencies.append(parts[-1].latency_s)
            if got is not None:
                tally.answered.append(parts[-1].latency_s)
        if got is None:
            tally.sorry += 1
        elif got == rule_id(clip.text):
            tally.right += 1
        else:
            tally.wrong += 1
            tally.mistakes.append(f"{clip.text!r} (age {clip.age}) heard {heard!r} -> {got}")
    return tallies


def pct(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q / 100 * (len(ordered) - 1)))]


def print_tallies(name: str, tallies: dict[str, BandTally]) -> None:
    for band, tally in sorted(tallies.items()):
        n = tally.clips
        answered, every = tally.answered or [0.0], tally.latencies or [0.0]
        print(
            f"{name:20s} {band:5s} right {tally.right:3d}/{n} ({100 * tally.right / n:5.1f}%)  "
            f"wrong {tally.wrong:2d}  sorry {tally.sorry:3d}   end of speech -> intent "
            f"p50 {statistics.median(answered) * 1000:4.0f} ms  "
            f"p90 {pct(answered, 90) * 1000:4.0f} ms (answered); "
            f"p90 {pct(every, 90) * 1000:4.0f} ms (all)"
        )
        for line in tally.mistakes:
            print(f"  wrong: {line}")


def children_figures(
    hearings: dict[str, tuple[Recognizer, bool]], vad: SileroVad, *, quick: bool
) -> None:
    """Prints the children's figures for each of ``hearings`` (name: recognizer, and
    whether it listens as to children); ``quick``: two clips a band, a check that it runs."""
    if not (CORPUS / "index.json").is_file():
        print(f"\n== children's voices: skipped ({CORPUS} is not here)")
        return
    tuning, held_back = split_corpus()
    if quick:
        held_back = [c for c in held_back if c.band == "6-8"][:2] + [
            c for c in held_back if c.band == "9-12"
        ][:2]
    everything = sentences_dialog([c.text for c in tuning + held_back])
    tuning_only = sentences_dialog([c.text for c in tuning])
    ages = sorted({c.age for c in held_back})
    print(
        f"\n== children's voices (speechocean762): {len(held_back)} clips of "
        f"{len({c.speaker for c in held_back})} held-back children aged {ages[0]}-{ages[-1]}"
    )
    print(
        "-- in the dialog (every sentence a rule): target 0 wrong, >= 60% right at 6-8, "
        ">= 80% at 9-12, p90 <= 500 ms"
    )
    for name, (recognizer, children) in hearings.items():
        tallies = hear_children(held_back, everything, recognizer, vad, children=children)
        print_tallies(name, tallies)
    print("-- out of the dialog (the tuning children's sentences only): every answer is wrong")
    for name, (recognizer, children) in hearings.items():
        tallies = hear_children(held_back, tuning_only, recognizer, vad, children=children)
        print_tallies(name, tallies)


def adults_out_of_the_dialog(recognizer: Recognizer, vad: SileroVad, dialog: Dialog) -> None:
    """The real adults' recordings (none of which ``dialog`` means) heard with children's
    hearing: prints how many were answered (target 0) and what."""
    sys.path.insert(0, str(ROOT / "tests" / "speech"))
    from real_voices import (  # type: ignore[import-not-found]  # the tests' own module
        missing_real_voices,
        real_voice_set,
    )

    missing = missing_real_voices()
    if missing is not None:
        print(f"-- adults out of the dialog: skipped ({missing})")
        return
    clips = real_voice_set()
    recognizer.listen_for(dialog.phrases)
    whole_turn = PhraseGrammar(dialog.phrases).is_a_whole_turn
    answered: list[str] = []
    for clip in clips:
        parts = heard_live(clip.audio, vad, recognizer, whole_turn, children=True)
        heard = " ".join(part.text for part in parts if part.text)
        verdict = dialog.judge(heard) if heard else None
        if verdict is not None and verdict.match is not None:
            answered.append(f"{clip.transcript!r} heard {heard!r} -> {verdict.match.rule.id}")
    print(
        f"-- adults out of the dialog ({len(clips)} recordings of people, {dialog.name}, "
        f"children's hearing): answered {len(answered)}   target 0"
    )
    for line in answered:
        print(f"  answered: {line}")

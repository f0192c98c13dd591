"""Real people's voices for the speech tests and benchmarks (issue 24): 43 short clips
with what is said in them, read from three Debian packages (REAL_VOICES.md: licenses).

The audio is not in this repository: it is read where Debian installs it (scripts/setup
installs the packages for ``all``). The list of clips and their transcripts is written
here, so the set never changes by itself; each transcript is checked against the one the
package ships, so a package that changed is noticed (:class:`RealVoicesChangedError`).

- pocketsphinx-testdata (16 kHz; transcripts lowercase, no punctuation): the five
  ``cards`` clips, the ``librivox`` clips of 5 s or less, and ``goforward.raw``.
- asterisk-core-sounds-en(-wav) (8 kHz, Allison Smith): 35 prompts. The candidates are the
  top-level prompts of 1 to 5 s whose transcript is an ordinary sentence (3 or more
  words, a capital first, a full stop, ! or ? last, no brackets, ellipses or digits),
  sorted by name, the first of each repeated text: 95 in package version 1.6.1; the
  clips are every (95/35)-th of those, ``candidates[i * 95 // 35]``.
"""

from __future__ import annotations

import gzip
import re
from dataclasses import dataclass
from pathlib import Path

from engine.errors import VestError
from engine.media.audio import Audio, read_wav

SPHINX_PACKAGE = "pocketsphinx-testdata"
PROMPTS_PACKAGE = "asterisk-core-sounds-en-wav"
PROMPT_TEXTS_PACKAGE = "asterisk-core-sounds-en"

SPHINX_DATA = Path("usr/share/pocketsphinx/test/data")
PROMPTS = Path("usr/share/asterisk/sounds/en_US_f_Allison")
"""The package's own folder: sounds/en is a link that Debian's alternatives may point at
another voice."""
PROMPT_TEXTS = Path("usr/share/doc/asterisk-core-sounds-en/core-sounds-en.txt.gz")
GOFORWARD_RATE_HZ = 16000
"""goforward.raw has no header: 16-bit little-endian mono at 16 kHz."""

CARDS = {
    "001": "ten of clubs",
    "002": "four queen of clubs",
    "003": "seven of clubs",
    "004": "five five",
    "005": "eight of spades four of clubs seven of hearts",
}
LIBRIVOX = {
    "sense_and_sensibility_01_austen_64kb-0880": "he was not an ill disposed young man",
    "sense_and_sensibility_01_austen_64kb-0930": "he might even have been made amiable himself",
}
GOFORWARD = "go forward ten meters"
ALLISON = {
    "agent-loggedoff": "Agent Logged off.",
    "agent-newlocation": "Please enter a new extension, followed by pound.",
    "all-circuits-busy-now": "All circuits are busy now.",
    "call-fwd-no-ans": "Call-Forward on No Answer.",
    "cannot-complete-as-dialed": "Your call cannot be completed as dialed.",
    "conf-full": "That conference is full.",
    "conf-getpin": "Please enter the conference pin number.",
    "conf-leaderhasleft": "The leader has left the conference.",
    "conf-noempty": "No empty conferences currently exist.",
    "conf-now-recording": "The conference is now being recorded.",
    "conf-onlyperson": "You are currently the only person in this conference.",
    "conf-roll-callcomplete": "Playback of the list of people attending is complete.",
    "confbridge-lock-no-join": "The conference is currently locked and cannot be joined.",
    "confbridge-only-participant": "You are currently the only participant in the conference.",
    "confbridge-unlocked": "The conference is now unlocked.",
    "demo-echodone": "The echo test has been completed.",
    "do-not-disturb": "Do not disturb.",
    "feature-not-avail-line": "That feature is not available on this line.",
    "info-about-last-call": "Information about your last call.",
    "is-set-to": "Is set to.",
    "pbx-invalidpark": "I am sorry, there is no call parked on that extension. Please try again.",
    "please-try-call-later": "Please try your call again later.",
    "pm-invalid-option": "That option is invalid. Please try again.",
    "privacy-incorrect": "I'm sorry, that number is not valid.",
    "simul-call-limit-reached": "Simultaneous call limit reached.",
    "sorry-youre-having-problems": "Sorry you're having problems.",
    "to-call-this-number": "To call this number.",
    "transfer": "Please hold while I try that extension.",
    "vm-helpexit": "Press star for help or pound to exit.",
    "vm-invalidpassword": "That is not a valid password. Please try again.",
    "vm-marked-urgent": "Message marked urgent.",
    "vm-msgsaved": "Your message has been saved.",
    "vm-nomore": "No more messages.",
    "vm-rec-name": "After the tone say your name and then press the pound key.",
    "vm-sorry": "I'm sorry I did not understand your response.",
}


class RealVoicesChangedError(VestError, ValueError):
    """An installed package does not hold a clip or transcript this module lists."""


@dataclass(frozen=True)
class RealVoiceClip:
    """One person saying one thing: ``name`` (``cards/001``, ``allison/vm-msgsaved``...),
    the Debian ``package`` it is read from, what is said (as the package writes it) and the
    audio at the package's own rate (resample it to 16 kHz for the recognizer)."""

    name: str
    package: str
    transcript: str
    audio: Audio


def missing_real_voices(root: Path = Path("/")) -> str | None:
    """Why the real-voice set cannot be read under ``root``, in words; None when it can."""
    needed = {
        SPHINX_PACKAGE: root / SPHINX_DATA / "cards" / "cards.transcription",
        PROMPTS_PACKAGE: root / PROMPTS / "vm-msgsaved.wav",
        PROMPT_TEXTS_PACKAGE: root / PROMPT_TEXTS,
    }
    absent = [package for package, path in needed.items() if not path.is_file()]
    if not absent:
        return None
    named = absent[0] if len(absent) == 1 else f"{', '.join(absent[:-1])} and {absent[-1]}"
    return (
        f"the real-voice set needs Debian's {named} "
        f"(scripts/setup installs {'it' if len(absent) == 1 else 'them'})"
    )


def real_voice_set(root: Path = Path("/")) -> list[RealVoiceClip]:
    """The 43 clips, in a fixed order: pocketsphinx's, then Allison Smith's. Raises
    RealVoicesChangedError when a package under ``root`` no longer matches the list."""
    data = root / SPHINX_DATA
    clips: list[RealVoiceClip] = []
    for folder, listed, texts in (
        ("cards", CARDS, data / "cards" / "cards.transcription"),
        ("librivox", LIBRIVOX, data / "librivox" / "transcription"),
    ):
        _check(listed, _sphinx_texts(texts), texts)
        clips += [
            RealVoiceClip(
                f"{folder}/{name}", SPHINX_PACKAGE, text, read_wav(data / folder / f"{name}.wav")
            )
            for name, text in listed.items()
        ]
    grammar = data / "goforward.gram"
    _check({"goforward": GOFORWARD}, {"goforward": _grammar_move(grammar)}, grammar)
    raw = (data / "goforward.raw").read_bytes()
    clips.append(
        RealVoiceClip(
            "goforward", SPHINX_PACKAGE, GOFORWARD, Audio.from_pcm16(raw, GOFORWARD_RATE_HZ)
        )
    )
    _check(ALLISON, _prompt_texts(root / PROMPT_TEXTS), root / PROMPT_TEXTS)
    clips += [
        RealVoiceClip(
            f"allison/{name}", PROMPTS_PACKAGE, text, read_wav(root / PROMPTS / f"{name}.wav")
        )
        for name, text in ALLISON.items()
    ]
    return clips


def _check(listed: dict[str, str], installed: dict[str, str], where: Path) -> None:
    """Each listed transcript is the installed one (its spaces collapsed)."""
    for name, text in listed.items():
        shipped = installed.get(name)
        if shipped is None or " ".join(shipped.split()) != text:
            raise RealVoicesChangedError(
                f"{where}: clip {name!r} is listed as {text!r} but the package has "
                f"{shipped!r}; the package changed: choose the clips again (real_voices.py)"
            )


_SPHINX_LINE = re.compile(r"<s>(.*)</s>\s*\((\S+)\)")


def _sphinx_texts(path: Path) -> dict[str, str]:
    """A pocketsphinx transcription file: ``<s> words </s> (id)`` a line."""
    texts: dict[str, str] = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        if found := _SPHINX_LINE.fullmatch(line.strip()):
            texts[found.group(2)] = found.group(1).strip()
    return texts


def _grammar_move(path: Path) -> str:
    """What goforward.raw says: the JSGF grammar's ``<move>`` rule, its one fixed
    sentence."""
    found = re.search(r"^public <move> = ([^;]*);", path.read_text(encoding="utf-8"), re.M)
    return found.group(1).strip() if found else ""


def _prompt_texts(path: Path) -> dict[str, str]:
    """Asterisk's core-sounds-en.txt.gz: ``name: Transcript.`` a line."""
    texts: dict[str, str] = {}
    with gzip.open(path, "rt", encoding="utf-8") as lines:
        for line in lines:
            name, colon, text = line.rstrip("\n").partition(": ")
            if colon and not name.startswith(";"):
                texts[name] = text
    return texts

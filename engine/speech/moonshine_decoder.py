"""Moonshine's decoder on one utterance: one text or several at once (rows), with its
key/value cache, for the free transcript and for closed listening's search
(:class:`~engine.speech.phrase_search.Decoding`). The encoder's part of the cache is the
same for every row: computed at the first step and repeated once for each number of rows,
never copied at each step. Each step first asks whether the utterance is still wanted
(:data:`~engine.speech.recognizer.Abandon`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from engine.speech.recognizer import Abandon


def log_softmax(logits: np.ndarray) -> np.ndarray:
    """Natural-log probabilities of each row of ``logits``."""
    top = logits.max(axis=-1, keepdims=True)
    shifted: np.ndarray = logits - top
    result: np.ndarray = shifted - np.log(np.exp(shifted).sum(axis=-1, keepdims=True))
    return result


class AbandonedError(Exception):
    """The utterance was abandoned while it was being decoded (:data:`Abandon`)."""


@dataclass(frozen=True)
class DecoderModel:
    """The merged decoder's ONNX Runtime session and the shape of its cache."""

    session: Any  # onnxruntime.InferenceSession
    cache_names: tuple[str, ...]
    empty: np.ndarray  # an empty cache entry: (1, heads, 0, size)
    outputs: tuple[str, ...]
    start_token: int

    @classmethod
    def of(cls, session: Any, start_token: int) -> DecoderModel:
        inputs = {i.name: i for i in session.get_inputs()}
        names = tuple(name for name in inputs if name.startswith("past_key_values."))
        heads, size = inputs[names[0]].shape[1], inputs[names[0]].shape[3]
        empty = np.zeros((1, int(heads), 0, int(size)), dtype=np.float32)
        outputs = tuple(o.name for o in session.get_outputs())
        return cls(session, names, empty, outputs, start_token)


class Decoder:
    """Moonshine's decoder on one utterance's encoder output, for one text or several at
    once (rows), with its key/value cache: a :class:`~engine.speech.phrase_search.Decoding`.
    Each step first asks ``abandon`` (None: never) and stops the search when it says so."""

    def __init__(self, model: DecoderModel, hidden: np.ndarray, abandon: Abandon | None) -> None:
        self._model = model
        self._abandon = abandon
        self._cache = {name: model.empty for name in model.cache_names}
        self._started = False
        self._first: tuple[np.ndarray, dict[str, np.ndarray]] | None = None
        self._encoder: dict[str, np.ndarray] = {}  # its part of the cache: the same each row
        self._repeated: dict[int, dict[str, np.ndarray]] = {1: {"encoder_hidden_states": hidden}}
        """The encoder's output and its part of the cache for so many rows."""

    def first(self) -> np.ndarray:
        if self._first is None:  # the first step is the same for every text: run once
            rows = self._run(np.array([[self._model.start_token]], dtype=np.int64))
            self._first = (rows, dict(self._cache))
        rows, self._cache = self._first[0], dict(self._first[1])
        self._started = True
        return rows

    def then(self, parents: np.ndarray, tokens: np.ndarray) -> np.ndarray:
        self._cache = {name: value[parents] for name, value in self._cache.items()}
        return self._run(tokens[:, None])

    def _for_rows(self, rows: int) -> dict[str, np.ndarray]:
        """What every row shares (the encoder's output and its part of the cache), for
        ``rows`` rows: repeated once for each count of rows, not copied at each step."""
        if rows not in self._repeated:
            one = {**self._repeated[1], **self._encoder}
            self._repeated[rows] = {name: np.repeat(v, rows, axis=0) for name, v in one.items()}
        return self._repeated[rows]

    def _run(self, ids: np.ndarray) -> np.ndarray:
        """Log-probabilities of the next token after each row of ``ids``."""
        if self._abandon is not None and self._abandon():
            raise AbandonedError
        outputs = self._model.session.run(
            None,
            {
                "input_ids": ids,
                "use_cache_branch": np.array([self._started]),
                **self._cache,
                **self._for_rows(len(ids)),
            },
        )
        for name, value in zip(self._model.outputs[1:], outputs[1:], strict=True):
            past = "past_key_values." + name.removeprefix("present.")
            if ".decoder." in past:
                self._cache[past] = value
            elif not self._started:  # the encoder's part is computed once, at the start
                self._encoder[past] = self._repeated[1][past] = value
                del self._cache[past]
        self._started = True
        return log_softmax(outputs[0][:, -1])

"""The finger-count network on ONNX Runtime: a model file and the settings beside it.

A model is ``NAME.onnx`` with ``NAME.json`` beside it: the labels, the preprocessing it was
trained with (:class:`~engine.vision.preprocess.Preprocessing`) and how it was trained.
It is opened as every vision model is (:mod:`engine.vision.onnx_session`), and the
providers in use are logged.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt
import onnxruntime as ort

from engine.errors import ConfigError
from engine.media.images import Frame
from engine.vision.onnx_session import onnx_session
from engine.vision.preprocess import Preprocessing, load_settings, network_input

log = logging.getLogger(__name__)
DEFAULT_MODEL = Path(__file__).resolve().parent / "models" / "hand_fingers.onnx"
"""The model the project ships (docs/vision-model-card.md says how it was made)."""
MODEL_FORMAT = "vest-gesture-model/1"


@dataclass(frozen=True)
class HandReading:
    """What one frame showed: ``fingers`` 0..5, or None when no hand was held up
    (``present`` False) or its count is not sure; ``confidence`` 0..1; the probability of
    every label (the paper's network; empty when the landmarks counted); ``box`` where the
    hand was (x, y, width, height px; None: no hand)."""

    fingers: int | None
    confidence: float
    probabilities: tuple[float, ...]
    present: bool = True
    box: tuple[int, int, int, int] | None = None

    def to_json(self) -> dict[str, Any]:
        names = ("x", "y", "width", "height")
        box = None if self.box is None else dict(zip(names, self.box, strict=True))
        return {
            "hand": self.present,
            "fingers": self.fingers,
            "confidence": round(self.confidence, 4),
            "box": box,
        }


class FingerCounter(Protocol):
    """What the vision worker needs of a model: a reading for one frame."""

    def read(self, frame: Frame) -> HandReading: ...


class HandModel:
    """A loaded finger-count model: an ONNX Runtime session and its preprocessing.

    :meth:`read` runs the preprocessing and the network for one frame (both release the
    GIL for most of their time); call it from a worker, never from a tick.
    """

    def __init__(
        self,
        session: ort.InferenceSession,
        settings: Preprocessing,
        labels: Sequence[int],
        *,
        min_confidence: float,
        path: Path,
    ) -> None:
        self.session = session
        self.settings = settings
        self.labels = tuple(labels)
        self.min_confidence = min_confidence
        self.path = path
        self.input_name = session.get_inputs()[0].name

    @classmethod
    def load(
        cls,
        path: Path = DEFAULT_MODEL,
        *,
        threads: int = 1,
        providers: Sequence[str] | None = None,
        min_confidence: float = 0.6,
    ) -> HandModel:
        """The model at ``path`` (and ``path`` with ``.json``); ConfigError naming the file
        when either is missing or not a model. ``threads``: ONNX Runtime's intra-op
        threads; ``min_confidence``: below it a frame reads as no count."""
        if not path.is_file():
            raise ConfigError(f"{path}: no such model file")
        sidecar = path.with_suffix(".json")
        data = load_settings(sidecar)
        if data.get("format") != MODEL_FORMAT:
            raise ConfigError(f"{sidecar}: 'format' must be {MODEL_FORMAT!r}")
        labels = data.get("labels")
        if (
            not isinstance(labels, list)
            or not labels
            or not all(
                isinstance(label, int) and not isinstance(label, bool) and 0 <= label <= 10
                for label in labels
            )
        ):
            raise ConfigError(f"{sidecar}: 'labels' must be a list of finger counts (0 to 10)")
        settings = Preprocessing.from_json(data.get("preprocessing", {}), str(sidecar))
        session = onnx_session(path, threads=threads, providers=providers)
        model = cls(session, settings, labels, min_confidence=min_confidence, path=path)
        model._check_shape()
        log.info("hand model %s runs on %s", path.name, ", ".join(session.get_providers()))
        return model

    @property
    def providers(self) -> list[str]:
        """The execution providers the session runs on, first preferred."""
        return list(self.session.get_providers())

    def _check_shape(self) -> None:
        shape = self.session.get_inputs()[0].shape
        side = self.settings.side_px
        if len(shape) != 4 or list(shape[1:]) != [1, side, side]:
            raise ConfigError(
                f"{self.path}: the network reads {shape}, but its settings make "
                f"1x{side}x{side} images"
            )
        outputs = self.session.get_outputs()[0].shape
        if outputs[-1] != len(self.labels):
            raise ConfigError(
                f"{self.path}: the network tells {outputs[-1]} classes apart, its settings "
                f"name {len(self.labels)} labels"
            )

    def probabilities(self, inputs: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
        """Each label's probability for a batch of network inputs (N, 1, side, side)."""
        (scores,) = self.session.run(None, {self.input_name: inputs})
        return _softmax_if_needed(np.asarray(scores, dtype=np.float32))

    def read_input(self, single: npt.NDArray[np.float32]) -> HandReading:
        """The reading for one preprocessed input (1, side, side)."""
        return self.reading(self.probabilities(single[np.newaxis])[0])

    def read(self, frame: Frame) -> HandReading:
        """The reading for one camera frame (or image): preprocessing and network."""
        return self.read_input(network_input(frame, self.settings))

    def reading(self, probabilities: npt.NDArray[np.float32]) -> HandReading:
        best = int(np.argmax(probabilities))
        confidence = float(probabilities[best])
        fingers = self.labels[best] if confidence >= self.min_confidence else None
        return HandReading(fingers, confidence, tuple(float(p) for p in probabilities))


def _softmax_if_needed(scores: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
    """The network ends in a softmax (table 2); scores that are not probabilities (a model
    exported without it) are turned into them."""
    sums = scores.sum(axis=-1, keepdims=True)
    if np.all(scores >= 0) and np.allclose(sums, 1.0, atol=1e-3):
        return scores
    shifted = np.exp(scores - scores.max(axis=-1, keepdims=True))
    result: npt.NDArray[np.float32] = (shifted / shifted.sum(axis=-1, keepdims=True)).astype(
        np.float32
    )
    return result

"""The finger-count network on ONNX Runtime: a model file and the settings beside it.

A model is ``NAME.onnx`` with ``NAME.json`` beside it: the labels, the preprocessing it was
trained with (:class:`~engine.vision.preprocess.Preprocessing`) and how it was trained.
The session's execution providers are chosen from what this onnxruntime build offers
(TensorRT, then CUDA, then the CPU; GPU builds are the separate ``onnxruntime-gpu``
package), and the ones in use are logged: asked for a provider it lacks, onnxruntime only
warns and falls back, so we filter first and say what runs.
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
from engine.vision.preprocess import Preprocessing, load_settings, network_input

log = logging.getLogger(__name__)
PREFERRED_PROVIDERS = (
    "TensorrtExecutionProvider",
    "CUDAExecutionProvider",
    "CPUExecutionProvider",
)
DEFAULT_MODEL = Path(__file__).resolve().parent / "models" / "hand_fingers.onnx"
"""The model the project ships (docs/vision-model-card.md says how it was made)."""
MODEL_FORMAT = "vest-gesture-model/1"


@dataclass(frozen=True)
class HandReading:
    """What the network saw in one frame: ``fingers`` 0..5, or None when it is not sure
    (its best class below the model's ``min_confidence``); ``confidence`` 0..1; the
    probability of every label."""

    fingers: int | None
    confidence: float
    probabilities: tuple[float, ...]

    def to_json(self) -> dict[str, Any]:
        return {"fingers": self.fingers, "confidence": round(self.confidence, 4)}


class FingerCounter(Protocol):
    """What the vision worker needs of a model: a reading for one frame."""

    def read(self, frame: Frame) -> HandReading: ...


def choose_providers(wanted: Sequence[str] | None = None) -> list[str]:
    """The execution providers to use: ``wanted`` (or the preferred order) filtered by what
    this onnxruntime offers; ConfigError when none of the wanted ones is there."""
    available = ort.get_available_providers()
    order = list(wanted) if wanted else list(PREFERRED_PROVIDERS)
    chosen = [name for name in order if name in available]
    if not chosen:
        raise ConfigError(
            f"none of the providers {', '.join(order)} is in this onnxruntime "
            f"(it has {', '.join(available)})"
        )
    return chosen


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
        options = ort.SessionOptions()
        options.intra_op_num_threads = max(1, threads)
        options.inter_op_num_threads = 1
        options.log_severity_level = 3  # errors only: we say which providers run
        chosen = choose_providers(providers)
        try:
            session = ort.InferenceSession(str(path), sess_options=options, providers=chosen)
        except Exception as error:  # onnxruntime raises its own error types for a bad file
            first = str(error).strip().splitlines()[0] if str(error).strip() else type(error)
            raise ConfigError(f"{path}: not a model ONNX Runtime can load ({first})") from None
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

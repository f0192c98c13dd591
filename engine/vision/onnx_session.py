"""Opening a model on ONNX Runtime, as every model of the robot's vision is opened.

The session's execution providers are chosen from what this onnxruntime build offers
(TensorRT, then CUDA, then the CPU; GPU builds are the separate ``onnxruntime-gpu``
package): asked for a provider it lacks, onnxruntime only warns and falls back, so we
filter first and say what runs.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import onnxruntime as ort

from engine.errors import ConfigError

PREFERRED_PROVIDERS = (
    "TensorrtExecutionProvider",
    "CUDAExecutionProvider",
    "CPUExecutionProvider",
)


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


def onnx_session(
    path: Path, *, threads: int = 1, providers: Sequence[str] | None = None
) -> ort.InferenceSession:
    """The model at ``path`` on ``threads`` intra-op threads; ConfigError naming the file
    when it is missing or not a model ONNX Runtime can load."""
    if not path.is_file():
        raise ConfigError(f"{path}: no such model file")
    options = ort.SessionOptions()
    options.intra_op_num_threads = max(1, threads)
    options.inter_op_num_threads = 1
    options.log_severity_level = 3  # errors only: we say which providers run
    chosen = choose_providers(providers)
    try:
        return ort.InferenceSession(str(path), sess_options=options, providers=chosen)
    except Exception as error:  # onnxruntime raises its own error types for a bad file
        first = str(error).strip().splitlines()[0] if str(error).strip() else type(error)
        raise ConfigError(f"{path}: not a model ONNX Runtime can load ({first})") from None

"""Weights stored as int8 made float once, at load, instead of at every run.

Moonshine's ``.ort`` models keep their weights as int8 with a scale and an offset and turn
them back into floats inside the graph (``Cast -> Mul -> Add``, then a ``Transpose`` of the
32,768-word embedding inside the decoder's ``If``), and ONNX Runtime does not fold that
away: each decoder step spent 50 of its 66 ms rebuilding the same weights (measured on
this machine's CPU). Here the model is read through ONNX Runtime (its ``.ort`` format
written back as an ONNX graph, basic optimizations only, so nothing is tied to this CPU),
every node whose inputs are all constants is computed once with numpy, and the graph is
handed back as bytes for :class:`onnxruntime.InferenceSession`. The outputs are the same
numbers (float32 arithmetic in numpy instead of in the graph); the decoder step takes
13 ms. Nothing is written next to the model: the ONNX graph lives in a temporary folder.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

Fold = Callable[[Any, list[np.ndarray]], np.ndarray]


def _attribute(node: Any, name: str, default: Any = None) -> Any:
    from onnx import helper

    for attribute in node.attribute:
        if attribute.name == name:
            return helper.get_attribute_value(attribute)
    return default


def _cast(node: Any, inputs: list[np.ndarray]) -> np.ndarray:
    from onnx import helper

    return inputs[0].astype(helper.tensor_dtype_to_np_dtype(_attribute(node, "to")))


def _transpose(node: Any, inputs: list[np.ndarray]) -> np.ndarray:
    perm = _attribute(node, "perm")
    return np.ascontiguousarray(np.transpose(inputs[0], None if perm is None else list(perm)))


FOLDS: dict[str, Fold] = {
    "Cast": _cast,
    "Mul": lambda _, x: np.multiply(x[0], x[1]),
    "Add": lambda _, x: np.add(x[0], x[1]),
    "Sub": lambda _, x: np.subtract(x[0], x[1]),
    "Transpose": _transpose,
}
"""The operations folded: the ones that turn stored weights into the weights used."""


def folded_model(path: Path) -> bytes:
    """The model at ``path`` (``.onnx`` or ``.ort``) with its constant arithmetic done,
    as bytes for an InferenceSession. Raises what ONNX Runtime or onnx raise for a file
    that is not a model."""
    import onnx
    import onnxruntime
    from onnx import numpy_helper

    with tempfile.TemporaryDirectory(prefix="vest-model-") as folder:
        written = Path(folder) / "model.onnx"
        options = onnxruntime.SessionOptions()
        options.graph_optimization_level = onnxruntime.GraphOptimizationLevel.ORT_ENABLE_BASIC
        options.optimized_model_filepath = str(written)
        onnxruntime.InferenceSession(str(path), options, providers=["CPUExecutionProvider"])
        model = onnx.load(str(written))
    graph = model.graph
    constants = {tensor.name: numpy_helper.to_array(tensor) for tensor in graph.initializer}
    _fold(graph, constants)
    used = _inputs_used(graph) | {output.name for output in graph.output}
    kept = [
        numpy_helper.from_array(value, name) for name, value in constants.items() if name in used
    ]
    del graph.initializer[:]
    graph.initializer.extend(kept)
    _name_graphs(graph, "model")
    return bytes(model.SerializeToString())


def _fold(graph: Any, constants: dict[str, np.ndarray]) -> None:
    """Compute every node of ``graph`` (and of the graphs inside it) whose inputs are all
    known; its output joins ``constants`` and the node goes."""
    kept = []
    for node in graph.node:
        for attribute in node.attribute:
            if attribute.HasField("g"):
                _fold(attribute.g, constants)
        fold = FOLDS.get(node.op_type)
        if fold is not None and node.input and all(name in constants for name in node.input):
            constants[node.output[0]] = fold(node, [constants[name] for name in node.input])
        else:
            kept.append(node)
    del graph.node[:]
    graph.node.extend(kept)


def _inputs_used(graph: Any) -> set[str]:
    used: set[str] = set()
    for node in graph.node:
        used.update(node.input)
        for attribute in node.attribute:
            if attribute.HasField("g"):
                used |= _inputs_used(attribute.g)
    return used


def _name_graphs(graph: Any, name: str) -> None:
    """ONNX Runtime writes graphs without names, and refuses to read them back so."""
    graph.name = graph.name or name
    for node in graph.node:
        for attribute in node.attribute:
            if attribute.HasField("g"):
                _name_graphs(attribute.g, f"{name}_{node.name}_{attribute.name}")

"""Weights stored as int8 are made float once, at load: the model computes the same and
does no more of that arithmetic at each run (engine/speech/onnx_folding.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import onnx
import onnxruntime
from onnx import TensorProto, helper, numpy_helper

from engine.speech.onnx_folding import folded_model


def int8_weights_model(path: Path) -> np.ndarray:
    """A graph that turns int8 weights into floats (Cast, Mul, Add, Transpose) and
    multiplies its input by them, as Moonshine's do; returns the weights it means."""
    stored = np.arange(-6, 6, dtype=np.int8).reshape(3, 4)
    scale, offset = np.float32(0.5), np.float32(0.25)
    nodes = [
        helper.make_node("Cast", ["stored"], ["as_float"], to=TensorProto.FLOAT),
        helper.make_node("Mul", ["as_float", "scale"], ["scaled"]),
        helper.make_node("Add", ["scaled", "offset"], ["weights"]),
        helper.make_node("Transpose", ["weights"], ["turned"], perm=[1, 0]),
        helper.make_node("MatMul", ["x", "turned"], ["y"]),
    ]
    graph = helper.make_graph(
        nodes,
        "int8_weights",
        [helper.make_tensor_value_info("x", TensorProto.FLOAT, [1, 4])],
        [helper.make_tensor_value_info("y", TensorProto.FLOAT, [1, 3])],
        [
            numpy_helper.from_array(stored, "stored"),
            numpy_helper.from_array(np.array(scale), "scale"),
            numpy_helper.from_array(np.array(offset), "offset"),
        ],
    )
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)])
    model.ir_version = 8
    onnx.save(model, str(path))
    return (stored.astype(np.float32) * scale + offset).T


def test_a_folded_model_computes_the_same_without_the_weight_arithmetic(tmp_path: Path) -> None:
    weights = int8_weights_model(tmp_path / "model.onnx")
    folded = folded_model(tmp_path / "model.onnx")
    assert [node.op_type for node in onnx.load_from_string(folded).graph.node] == ["MatMul"]
    x = np.array([[1.0, -2.0, 0.5, 3.0]], dtype=np.float32)
    session = onnxruntime.InferenceSession(folded, providers=["CPUExecutionProvider"])
    np.testing.assert_allclose(session.run(None, {"x": x})[0], x @ weights, rtol=1e-6)
    original = onnxruntime.InferenceSession(
        str(tmp_path / "model.onnx"), providers=["CPUExecutionProvider"]
    )
    np.testing.assert_array_equal(session.run(None, {"x": x})[0], original.run(None, {"x": x})[0])

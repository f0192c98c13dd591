"""The table-2 network in PyTorch: its size, its ONNX export against PyTorch, and a short
training run on drawn hands that writes a model the robot can load."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip(
    "torch", reason="training needs the train extra: pip install -e .[train]"
)

from engine.vision.classifier import HandModel  # noqa: E402
from engine.vision_training.hand_network import (  # noqa: E402
    HandNetwork,
    WithSoftmax,
    export_onnx,
    parameter_count,
)
from engine.vision_training.synthetic_hands import write_dataset  # noqa: E402
from engine.vision_training.training import (  # noqa: E402
    TrainingSettings,
    learning_rate_factor,
    soft_targets,
    train,
)


def test_the_network_is_table_2_with_its_1_64_million_parameters() -> None:
    network = HandNetwork()
    assert parameter_count(network) == 1_640_006
    convolutions = [m for m in network.features if isinstance(m, torch.nn.Conv2d)]
    assert [c.out_channels for c in convolutions] == [8, 16, 32, 64, 128, 256, 512]
    assert all(c.kernel_size == (3, 3) and c.padding == (1, 1) for c in convolutions)
    shape = network.features(torch.zeros(1, 1, 128, 128)).shape
    assert tuple(shape) == (1, 512, 1, 1)


def test_the_exported_model_answers_as_pytorch_does(tmp_path: Path) -> None:
    torch.manual_seed(5)
    network = HandNetwork().eval()
    path = tmp_path / "hands.onnx"
    export_onnx(network, path)
    assert not list(tmp_path.glob("*.data"))  # one file, its weights inside
    (tmp_path / "hands.json").write_text(
        json.dumps({"format": "vest-gesture-model/1", "labels": [0, 1, 2, 3, 4, 5]})
    )
    model = HandModel.load(path)
    images = (np.random.default_rng(1).random((4, 1, 128, 128)) < 0.15).astype(np.float32)
    with torch.no_grad():
        expected = WithSoftmax(network)(torch.from_numpy(images)).numpy()
    got = model.probabilities(images)
    # float32 sums in another order (ONNX Runtime's kernels for this CPU, PyTorch's): a few
    # parts in a million apart on some machines, the same answer on all of them
    np.testing.assert_allclose(got, expected, atol=1e-5)
    np.testing.assert_allclose(got.sum(axis=1), 1.0, atol=1e-5)


def test_no_hand_is_trained_towards_every_count_alike() -> None:
    targets = soft_targets(np.array([2, 6]))
    assert targets[0].tolist() == [0, 0, 1, 0, 0, 0]
    np.testing.assert_allclose(targets[1], [1 / 6] * 6)


def test_a_short_training_run_writes_a_model_and_its_settings(tmp_path: Path) -> None:
    data = tmp_path / "hands"
    write_dataset(data, 48, seed=3)
    out = tmp_path / "model" / "lab.onnx"
    lines: list[str] = []
    settings = TrainingSettings(epochs=2, batch=16, split_by="file", threads=1, warmup_steps=2)
    result = train(data, out, settings, lines.append)

    assert lines[0].startswith("48 pictures: training on 41, holding out 7 (by picture")
    assert lines[-1].startswith("epoch 2/2: loss ")
    assert result.evaluation.matrix.sum() == 7
    sidecar = json.loads(out.with_suffix(".json").read_text())
    assert sidecar["labels"] == [0, 1, 2, 3, 4, 5]
    assert sidecar["preprocessing"]["blur_sigma"] == 7.0
    assert sidecar["training"]["epochs"] == 2
    assert sidecar["training"]["held_out_evaluation"]["matrix"] == result.evaluation.matrix.tolist()
    assert HandModel.load(out).read(np.zeros((360, 640, 3), np.uint8)).confidence > 0


def test_a_short_fine_tuning_run_is_not_all_warm_up() -> None:
    """300 warm-up steps in a run of 10 epochs of 30 steps would leave no step at the full
    rate: the warm-up is at most a fifth of the run."""
    short = TrainingSettings(epochs=10, warmup_steps=300)
    assert learning_rate_factor(0, 30, short) == 0.1
    assert learning_rate_factor(60, 30, short) == 1.0  # a fifth of 300 steps: warm
    assert learning_rate_factor(200, 30, short) == 0.5  # past 60 % of the epochs
    long = TrainingSettings(epochs=16, warmup_steps=300)
    assert learning_rate_factor(150, 500, long) == 0.1 + 0.9 * 150 / 300

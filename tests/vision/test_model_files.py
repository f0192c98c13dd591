"""A model file is a .onnx with its .json beside it; a missing or broken one is named,
and the providers are chosen from what this onnxruntime has."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import onnxruntime as ort
import pytest

from engine.errors import ConfigError
from engine.vision.classifier import DEFAULT_MODEL, HandModel
from engine.vision.onnx_session import choose_providers


def copy_of_the_shipped_model(folder: Path) -> Path:
    path = folder / "copy.onnx"
    shutil.copy(DEFAULT_MODEL, path)
    shutil.copy(DEFAULT_MODEL.with_suffix(".json"), path.with_suffix(".json"))
    return path


@pytest.mark.models
def test_the_shipped_model_reads_one_128_square_edge_image_and_runs_on_the_cpu() -> None:
    model = HandModel.load()
    assert model.session.get_inputs()[0].shape[1:] == [1, 128, 128]
    assert model.labels == (0, 1, 2, 3, 4, 5)
    assert "CPUExecutionProvider" in model.providers


def test_a_missing_model_is_named(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"kids\.onnx: no such model file"):
        HandModel.load(tmp_path / "kids.onnx")


def test_a_model_without_its_settings_says_where_they_belong(tmp_path: Path) -> None:
    path = copy_of_the_shipped_model(tmp_path)
    path.with_suffix(".json").unlink()
    with pytest.raises(
        ConfigError, match=r"copy\.json: no such file \(a model's settings sit beside it\)"
    ):
        HandModel.load(path)


def test_a_corrupt_model_is_named_not_a_traceback(tmp_path: Path) -> None:
    path = copy_of_the_shipped_model(tmp_path)
    path.write_bytes(path.read_bytes()[:5000])  # cut short, as by a failed copy
    with pytest.raises(ConfigError, match=r"copy\.onnx: not a model ONNX Runtime can load"):
        HandModel.load(path)


def test_settings_of_another_kind_of_model_are_refused(tmp_path: Path) -> None:
    path = copy_of_the_shipped_model(tmp_path)
    path.with_suffix(".json").write_text(json.dumps({"format": "yolo", "labels": [0]}))
    with pytest.raises(ConfigError, match="'format' must be 'vest-gesture-model/1'"):
        HandModel.load(path)


def test_labels_that_do_not_match_the_network_are_refused(tmp_path: Path) -> None:
    path = copy_of_the_shipped_model(tmp_path)
    sidecar = json.loads(path.with_suffix(".json").read_text())
    sidecar["labels"] = [0, 1, 2]
    path.with_suffix(".json").write_text(json.dumps(sidecar))
    with pytest.raises(ConfigError, match="tells 6 classes apart, its settings name 3 labels"):
        HandModel.load(path)


def test_providers_are_those_this_onnxruntime_has_in_the_preferred_order() -> None:
    chosen = choose_providers()
    assert chosen[-1] == "CPUExecutionProvider"
    assert all(name in ort.get_available_providers() for name in chosen)


def test_asking_only_for_a_provider_this_build_lacks_is_refused() -> None:
    if "TensorrtExecutionProvider" in ort.get_available_providers():
        pytest.skip("this onnxruntime has TensorRT")
    with pytest.raises(ConfigError, match="none of the providers TensorrtExecutionProvider"):
        choose_providers(["TensorrtExecutionProvider"])


@pytest.mark.parametrize("labels", [[-7, 1, 2, 3, 4, 5], [0, 1, 2, 3, 4, 10**30], [0, 1.5]])
def test_labels_that_are_not_finger_counts_are_refused(tmp_path: Path, labels: list[Any]) -> None:
    path = copy_of_the_shipped_model(tmp_path)
    sidecar = json.loads(path.with_suffix(".json").read_text())
    sidecar["labels"] = labels
    path.with_suffix(".json").write_text(json.dumps(sidecar))
    with pytest.raises(ConfigError, match=r"must be a list of finger counts \(0 to 10\)"):
        HandModel.load(path)

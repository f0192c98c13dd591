"""The robot config's camera: a webcam and the hand model it feeds; each mistake named
with its place."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.files.problems import LoadError
from engine.hardware.config import RobotConfig
from engine.hardware.config_file import load_robot_config

ROBOT = "name: test\nbuses:\n  i2c: {kind: i2c, number: 1}\ndevices: {}\n"
SIMULATED = "name: test\nsimulated: true\nbuses:\n  i2c: {kind: i2c, number: 1}\ndevices: {}\n"


def load(tmp_path: Path, text: str) -> RobotConfig:
    path = tmp_path / "robot.yaml"
    path.write_text(text)
    return load_robot_config(path, "robot.yaml")


def problems(tmp_path: Path, text: str) -> list[str]:
    with pytest.raises(LoadError) as caught:
        load(tmp_path, text)
    return [str(problem) for problem in caught.value.problems]


def test_a_robot_has_no_camera_unless_its_config_names_one(tmp_path: Path) -> None:
    assert load(tmp_path, ROBOT).camera is None


def test_a_simulated_vest_has_the_simulated_camera_unless_told_none(tmp_path: Path) -> None:
    camera = load(tmp_path, SIMULATED).camera
    assert camera is not None and camera.simulated
    assert (camera.width, camera.height, camera.fps, camera.crop) == (640, 360, 15.0, None)
    assert load(tmp_path, SIMULATED + "camera: none\n").camera is None


def test_a_webcam_with_its_window_and_a_model_beside_the_config(tmp_path: Path) -> None:
    text = ROBOT + (
        "camera: {device: /dev/video2, fps: 30, crop: [100, 50], model: models/kids.onnx,"
        " threads: 2, providers: [CPUExecutionProvider], steady_frames: 5}\n"
    )
    camera = load(tmp_path, text).camera
    assert camera is not None
    assert (camera.device, camera.fps, camera.crop) == ("/dev/video2", 30.0, (100, 50))
    assert camera.model == tmp_path / "models" / "kids.onnx"
    assert camera.providers == ("CPUExecutionProvider",)
    assert (camera.threads, camera.steady_frames) == (2, 5)


def test_every_mistake_in_the_camera_section_is_named_with_its_place(tmp_path: Path) -> None:
    text = ROBOT + (
        "camera:\n"
        "  device: simulated\n"
        "  fsp: 30\n"
        "  crop: [600, 0]\n"
        "  providers: [CUDA]\n"
        "  min_confidence: 2\n"
    )
    found = problems(tmp_path, text)
    joined = "\n".join(found)
    assert "robot.yaml:6:11: the simulated camera needs a simulated vest" in joined
    assert "robot.yaml:7:3: unknown camera field 'fsp'" in joined and "fps" in joined
    assert "the 128x128 window at [600, 0] does not fit a 640x360 frame" in joined
    assert "camera 'providers' must be auto or a list of" in joined
    assert "robot.yaml:10:" in joined and "min_confidence" in joined


def test_a_robot_camera_needs_its_device(tmp_path: Path) -> None:
    [problem] = problems(tmp_path, ROBOT + "camera: {fps: 10}\n")
    assert "camera needs 'device' on a robot" in problem


def test_a_device_called_camera_beside_the_camera_is_named(tmp_path: Path) -> None:
    text = SIMULATED.replace("devices: {}", "devices:\n  camera: {chip: mpr121}")
    found = problems(tmp_path, text)
    assert any("a device may not be called 'camera'" in problem for problem in found)

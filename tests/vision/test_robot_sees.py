"""The robot sees: the shipped model counts drawn hands it never saw; the simulated camera
plays the finger game end to end; a missing model leaves the rest of the robot running;
`vest devices` probes the camera and the model."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from engine.cli import main
from engine.vision.classifier import HandModel
from engine.vision_training.dataset import centred_inputs
from engine.vision_training.evaluation import Evaluation
from engine.vision_training.synthetic_hands import render_frame

pytestmark = pytest.mark.models

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(
    ("style", "at_least"), [("studio", 0.88), ("wallpaper", 0.86), ("varied", 0.8)]
)
def test_the_shipped_model_counts_fingers_it_never_saw(style: str, at_least: float) -> None:
    """Frames drawn with a seed no training stage used (docs/vision-model-card.md)."""
    model = HandModel.load()
    rng = np.random.default_rng(4711)
    labels = np.arange(240) % 6
    frames = [render_frame(int(n), rng, style=style) for n in labels]
    probabilities = np.concatenate(
        [
            model.probabilities(centred_inputs(frames[i : i + 60], model.settings))
            for i in range(0, 240, 60)
        ]
    )
    right = float((probabilities.argmax(axis=1) == labels).mean())
    assert right >= at_least, Evaluation.of(probabilities, labels, model.min_confidence).table()


def test_an_empty_room_is_not_a_count() -> None:
    model = HandModel.load()
    rng = np.random.default_rng(4712)
    readings = [model.read(render_frame(None, rng)) for _ in range(30)]
    assert sum(r.fingers is None for r in readings) >= 27


def run_timeline(capsys, *args: str) -> str:
    assert main(["run", "--fast", "--speech", "text", *args]) == 0
    return capsys.readouterr().out


def test_the_finger_game_plays_on_the_simulated_camera(capsys, monkeypatch) -> None:
    monkeypatch.chdir(ROOT)
    out = run_timeline(
        capsys,
        "--scenario",
        "examples/scenarios/finger_game.yaml",
        "--trees",
        "trees/finger_game.yaml",
    )
    said = re.findall(r'finger_game +says "([^"]+)"', out)
    assert said[:3] == [
        "Let's play a counting game!",
        "Show me three fingers!",
        "Yes! That's three. Well done!",
    ]
    assert "Almost! Let's count together: one, two. Show me two." in said  # four, not two
    assert "Yes! That's two. Well done!" in said
    assert re.search(r"vest +sees 5 fingers held up", out)
    assert re.search(r"vest +camera is offline", out) and re.search(r"camera is back online", out)
    assert "Yes! That's five. Well done!" in said  # after the camera came back


def test_the_demo_plays_one_round_of_the_game(capsys, monkeypatch) -> None:
    monkeypatch.chdir(ROOT)
    out = run_timeline(capsys)
    said = re.findall(r'finger_game +says "([^"]+)"', out)
    assert said[:3] == [
        "Let's play a counting game!",
        "Show me three fingers!",
        "Yes! That's three. Well done!",
    ]


def test_a_missing_model_is_said_at_start_up_and_the_rest_of_the_robot_runs(
    tmp_path: Path, capsys, monkeypatch
) -> None:
    monkeypatch.chdir(ROOT)
    config = tmp_path / "robot.yaml"
    text = (ROOT / "examples" / "robots" / "sim.yaml").read_text()
    config.write_text(text + "\ncamera: {model: kids.onnx}\n")
    assert main(["run", "--fast", "--speech", "text", "--hardware", str(config)]) == 0
    captured = capsys.readouterr()
    assert "warning: camera: " in captured.err
    assert "kids.onnx: no such model file; the robot runs without counting fingers" in captured.err
    assert 'hug            says "I love hugs!"' in captured.out
    assert not re.search(r"finger_game +says", captured.out)  # no eyes, no game


def test_a_corrupt_model_is_said_at_start_up_too(tmp_path: Path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(ROOT)
    (tmp_path / "kids.onnx").write_bytes(b"\x08\x07 not a model")
    (tmp_path / "kids.json").write_text(
        '{"format": "vest-gesture-model/1", "labels": [0, 1, 2, 3, 4, 5]}'
    )
    config = tmp_path / "robot.yaml"
    text = (ROOT / "examples" / "robots" / "sim.yaml").read_text()
    config.write_text(text + "\ncamera: {model: kids.onnx}\n")
    assert main(["run", "--fast", "--speech", "text", "--hardware", str(config)]) == 0
    assert "kids.onnx: not a model ONNX Runtime can load" in capsys.readouterr().err


def test_vest_devices_opens_the_camera_and_runs_the_model_once(capsys, monkeypatch) -> None:
    monkeypatch.chdir(ROOT)
    assert main(["devices", "--no-speech"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^camera +webcam \(OpenCV\) +simulated vest +640x360 px", out, re.M)
    assert re.search(
        r"^hand model +CNN \(ONNX\) +hand_fingers\.onnx +input \S+x1x128x128, on CPU", out, re.M
    )
    assert re.search(r"(not sure|\d fingers) \(\d+%\) in [\d.]+ ms", out)

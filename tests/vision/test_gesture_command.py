"""`vest gesture`: count fingers in pictures, and make a lab's own model from recordings."""

from __future__ import annotations

import json
import os
from pathlib import Path

import cv2
import numpy as np
import pytest

from engine.cli import main
from engine.vision_training.synthetic_hands import render_frame

pytestmark = pytest.mark.models

REAL_HANDS = Path(__file__).resolve().parents[2] / "examples" / "hands-real"
ARMS_LENGTH = Path(__file__).resolve().parents[2] / "examples" / "hands-arms-length"


def exit_code(args: list[str]) -> int | str | None:
    """What `vest` exits with (argparse exits on its own for a wrong command line)."""
    try:
        return main(args)
    except SystemExit as done:
        return done.code


def picture(folder: Path, name: str, fingers: int | None, seed: int) -> Path:
    path = folder / name
    cv2.imwrite(str(path), render_frame(fingers, np.random.default_rng(seed)))
    return path


def test_pictures_are_counted_one_json_line_each(capsys) -> None:
    """Webcam frames of a person holding up fingers at arm's length: where the hand is, and
    its count."""
    three, five = ARMS_LENGTH / "3" / "three_1.jpg", ARMS_LENGTH / "5" / "five_1.jpg"
    assert main(["gesture", str(three), str(five), "--json"]) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(line["file"], line["hand"], line["fingers"]) for line in lines] == [
        (str(three), True, 3),
        (str(five), True, 5),
    ]
    box = lines[0]["box"]
    assert set(box) == {"x", "y", "width", "height"} and 40 < box["width"] < 320
    assert 0 <= box["x"] < 640 and 0 <= box["y"] < 480 and lines[0]["close_up"] is False


def test_a_frame_with_no_hand_held_up_says_so_never_a_count(capsys) -> None:
    """An empty room, and a room where a hand rests on a chair: no hand is not "not sure"."""
    for room in ("office_10.jpg", "office_35.jpg"):
        assert main(["gesture", str(ARMS_LENGTH / "none" / room), "--json"]) == 0
        said = json.loads(capsys.readouterr().out)
        assert (said["hand"], said["fingers"], said["box"]) == (False, None, None), room
        assert main(["gesture", str(ARMS_LENGTH / "none" / room)]) == 0
        assert capsys.readouterr().out.endswith(f"{room}: no hand held up\n")


def test_a_picture_reads_as_words_without_json(capsys) -> None:
    two = ARMS_LENGTH / "2" / "two_106.jpg"
    assert main(["gesture", str(two), "--json"]) == 0
    said = json.loads(capsys.readouterr().out)
    assert main(["gesture", str(two)]) == 0
    box = said["box"]
    where = f"{box['x']},{box['y']}, {box['width']}x{box['height']} px"
    assert capsys.readouterr().out == (
        f"{two}: 2 fingers ({said['confidence']:.0%}) (the hand at {where}, in a 640x480 px "
        "picture)\n"
    )


def test_a_window_elsewhere_is_given_with_crop(tmp_path: Path, capsys) -> None:
    frame = np.full((400, 400, 3), 90, np.uint8)
    photo = REAL_HANDS / "held-out" / "4" / "p005-IMG_1162.jpg"  # 100 x 100 px, four fingers
    frame[10:110, 20:120] = cv2.imread(str(photo))
    path = tmp_path / "corner.png"
    cv2.imwrite(str(path), frame)
    assert main(["gesture", str(path), "--crop", "20,10,100", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["fingers"] == 4


def test_bad_pictures_are_named_and_the_others_still_counted(tmp_path: Path, capsys) -> None:
    good = ARMS_LENGTH / "1" / "one_107.jpg"
    (tmp_path / "notes.png").write_text("not a picture")
    args = ["gesture", str(tmp_path / "notes.png"), str(good), str(tmp_path / "gone.png")]
    assert main(args) == 1
    captured = capsys.readouterr()
    assert captured.out.startswith(f"{good}: 1 finger (")
    assert "notes.png: not a picture vest reads" in captured.err
    assert "gone.png: file not found" in captured.err
    assert "Traceback" not in captured.err


def test_a_photograph_smaller_than_the_window_is_a_close_up_the_paper_s_network_counts(
    capsys,
) -> None:
    """The close-up photographs beside the project are 100 x 100 px, the window 128."""
    photo = next((REAL_HANDS / "held-out" / "3").glob("*.jpg"))
    assert main(["gesture", str(photo)]) == 0
    said = capsys.readouterr().out
    assert said.startswith(f"{photo}: 3 fingers (")
    assert said.endswith("(a 100x100 px close-up, counted by the paper's network)\n")
    assert main(["gesture", str(photo), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["close_up"] is True


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--crop", "1,2"], "must be X,Y,W in px"),
        (["--crop=-5,0,128"], "X and Y must be 0 or more"),
        (["--crop", "600,300,128"], "does not fit a 640x360 image"),
        (["--model", "nowhere/kids.onnx"], "kids.onnx: no such model file"),
    ],
)
def test_a_wrong_option_is_said_in_one_line(tmp_path: Path, capsys, args, message) -> None:
    image = picture(tmp_path, "a.png", 0, seed=16)
    assert exit_code(["gesture", str(image), *args]) in (1, 2)
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_a_lab_generates_trains_and_checks_its_own_model(tmp_path: Path, capsys) -> None:
    pytest.importorskip("torch", reason="training needs the train extra")
    data, model = tmp_path / "data", tmp_path / "lab.onnx"
    assert main(["gesture", "generate", str(data), "--count", "36", "--seed", "4"]) == 0
    assert sum(1 for _ in data.rglob("*.png")) == 36
    args = ["gesture", "train", str(data), "-o", str(model), "--epochs", "1", "--split", "file"]
    assert main([*args, "--threads", "1"]) == 0
    out = capsys.readouterr().out
    assert "epoch 1/1: loss" in out and "shows \\ said" in out and "held out: accuracy" in out
    assert model.is_file() and model.with_suffix(".json").is_file()
    assert model.with_suffix(".matrix.png").is_file()

    assert main(["gesture", "eval", str(data), "--model", str(model), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert sum(map(sum, report["matrix"])) == 36
    assert report["columns"][-1] == "not sure"


def test_a_model_learns_from_photographs_and_drawn_hands_together(tmp_path: Path, capsys) -> None:
    """Several folders at once, nothing held out (measured elsewhere), the preprocessing
    chosen: what scripts/train-hand-model's last stage does, in miniature."""
    pytest.importorskip("torch", reason="training needs the train extra")
    drawn, model = tmp_path / "drawn", tmp_path / "mixed.onnx"
    assert main(["gesture", "generate", str(drawn), "--count", "12", "--seed", "5"]) == 0
    photos = tmp_path / "photos"
    for count in ("2", "5"):
        (photos / count).mkdir(parents=True)
        for photo in sorted((REAL_HANDS / "train" / count).glob("*.jpg"))[:3]:
            (photos / count / photo.name).write_bytes(photo.read_bytes())
    args = ["gesture", "train", str(photos), str(drawn), "-o", str(model), "--epochs", "1"]
    assert main([*args, "--held-out", "0.00", "--preprocess", "edges", "--threads", "1"]) == 0
    out = capsys.readouterr().out
    assert "18 pictures: training on 18, holding out 0 (none held out)" in out
    assert "nothing held out: measure it with" in out
    sidecar = json.loads(model.with_suffix(".json").read_text())
    assert sidecar["preprocessing"]["mode"] == "edges"
    assert sidecar["training"]["data"] == ["photos", "drawn"]
    assert sidecar["training"]["held_out_evaluation"] is None

    # a lab's own pictures first: its test comes from them alone, never from pictures the
    # model it starts from may have seen
    args = ["gesture", "train", str(photos), str(drawn), "-o", str(model), "--epochs", "1"]
    assert main([*args, "--held-out", "0.5", "--split", "file", "--threads", "1"]) == 0
    out = capsys.readouterr().out
    assert "holding out 3 (by picture, of photos only)" in out


def test_training_on_a_folder_that_is_not_labelled_is_refused(tmp_path: Path, capsys) -> None:
    pytest.importorskip("torch", reason="training needs the train extra")
    (tmp_path / "data" / "seven").mkdir(parents=True)
    args = ["gesture", "train", str(tmp_path / "data"), "-o", str(tmp_path / "m.onnx")]
    assert main(args) == 1
    err = capsys.readouterr().err
    assert "seven: not a label folder (they are 0, 1, 2, 3, 4, 5, none)" in err


def test_record_takes_frames_from_a_camera_into_a_labelled_session(tmp_path: Path, capsys) -> None:
    """A video file stands in for the webcam: OpenCV opens both the same way."""
    video = tmp_path / "webcam.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter.fourcc(*"MJPG"), 15.0, (640, 360))
    rng = np.random.default_rng(5)
    for _ in range(30):
        writer.write(render_frame(2, rng))
    writer.release()
    data = tmp_path / "data"
    args = ["gesture", "record", str(data), "--camera", str(video), "--label", "2"]
    assert main([*args, "--frames", "5", "--session", "anna_1"]) == 0
    saved = sorted(p.name for p in (data / "2").iterdir())
    assert saved == [f"anna_1-{n:05d}.png" for n in range(5)]
    assert "5 pictures of 2" in capsys.readouterr().out

    assert main([*args, "--frames", "2", "--session", "anna_1"]) == 0  # numbered after those
    assert len(list((data / "2").iterdir())) == 7


def test_record_adds_pictures_from_a_folder_and_skips_what_it_cannot_use(
    tmp_path: Path, capsys
) -> None:
    source = tmp_path / "empty_room"
    source.mkdir()
    picture(source, "a.png", None, seed=6)
    (source / "b.png").write_text("broken")
    data = tmp_path / "data"
    args = ["gesture", "record", str(data), "--label", "none", "--from", str(source)]
    assert main([*args, "--session", "room"]) == 0
    assert [p.name for p in (data / "none").iterdir()] == ["room-00000.png"]
    assert "skipped" in capsys.readouterr().out


def test_record_takes_a_folder_laid_out_by_count_at_once(tmp_path: Path, capsys) -> None:
    source = tmp_path / "old_session"
    for label, fingers in (("2", 2), ("none", None)):
        (source / label).mkdir(parents=True)
        picture(source / label, "a.png", fingers, seed=7)
    data = tmp_path / "data"
    assert main(["gesture", "record", str(data), "--from", str(source), "--session", "s1"]) == 0
    assert [p.name for p in (data / "2").iterdir()] == ["s1-00000.png"]
    assert [p.name for p in (data / "none").iterdir()] == ["s1-00000.png"]
    assert "2 pictures (2, none)" in capsys.readouterr().out


def test_generating_or_training_into_a_place_that_cannot_be_written_is_said_first(
    tmp_path: Path, capsys
) -> None:
    blocked = tmp_path / "file"
    blocked.write_text("not a folder")
    assert main(["gesture", "generate", str(blocked / "data"), "--count", "2"]) == 1
    assert "cannot write there" in capsys.readouterr().err
    data = tmp_path / "data"
    assert main(["gesture", "generate", str(data), "--count", "6"]) == 0
    assert main(["gesture", "train", str(data), "-o", str(blocked / "m.onnx")]) == 1
    err = capsys.readouterr().err
    assert "cannot write there" in err and "epoch" not in err


@pytest.mark.parametrize("blocker", ["m.json", "m.matrix.png", "m.onnx"])
def test_a_model_s_files_that_could_not_be_written_are_named_before_the_training(
    tmp_path: Path, capsys, blocker: str
) -> None:
    """Found out after an hour of training, a folder or a FIFO where the model's settings go
    lost the run (a traceback, or a wait for ever)."""
    data = tmp_path / "data"
    assert main(["gesture", "generate", str(data), "--count", "6"]) == 0
    out = tmp_path / "out"
    out.mkdir()
    if blocker == "m.json":
        os.mkfifo(out / blocker)
    else:
        (out / blocker).mkdir()
    assert main(["gesture", "train", str(data), "-o", str(out / "m.onnx")]) == 1
    captured = capsys.readouterr()
    assert f"{blocker}: not a file the training can write" in captured.err
    assert "epoch" not in captured.out


def test_training_refuses_a_folder_named_twice_and_pictures_with_no_hand(
    tmp_path: Path, capsys
) -> None:
    data = tmp_path / "data"
    assert main(["gesture", "generate", str(data), "--count", "6"]) == 0
    model = str(tmp_path / "m.onnx")
    assert main(["gesture", "train", str(data), f"{data}/", "-o", model]) == 1
    assert "named twice; name each folder of pictures once" in capsys.readouterr().err
    empty_rooms = tmp_path / "rooms" / "none"
    empty_rooms.mkdir(parents=True)
    picture(empty_rooms, "room.png", None, seed=8)
    assert main(["gesture", "train", str(empty_rooms.parent), "-o", model]) == 1
    assert "no pictures of a hand (0/ .. 5/ are empty)" in capsys.readouterr().err


def test_record_takes_photographs_smaller_than_the_window(tmp_path: Path, capsys) -> None:
    data = tmp_path / "data"
    photos = REAL_HANDS / "train" / "3"
    assert main(["gesture", "record", str(data), "--label", "3", "--from", str(photos)]) == 0
    assert len(list((data / "3").iterdir())) == len(list(photos.iterdir()))


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--label", "7"], "must be one of 0, 1, 2, 3, 4, 5, none"),
        (["--from", "nowhere"], "nowhere: no such folder"),
        (["--frames", "3"], "--frames needs --label"),
        (["--label", "2", "--session", "a-b"], "no '-': it ends a session"),
        (["--label", "2", "--camera", "/dev/video63"], "camera /dev/video63: cannot be opened"),
    ],
)
def test_record_says_what_is_wrong_in_one_line(tmp_path: Path, capsys, args, message) -> None:
    assert exit_code(["gesture", "record", str(tmp_path / "data"), *args]) in (1, 2, 3)
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err

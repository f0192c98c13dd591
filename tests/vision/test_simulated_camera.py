"""The simulated vest's camera: what a scenario holds up to it (a person holding up
fingers, a picture seen whole, held at a distance or up close, a video) becomes frames;
it can be unplugged; bad show_hand events are named."""

from __future__ import annotations

import os
import textwrap
from pathlib import Path

import cv2
import numpy as np
import pytest

from engine.clock import VirtualClock
from engine.files.problems import LoadError
from engine.media.camera import CameraError
from engine.scenario.player import ScenarioPlayer
from engine.scenario.scenario_file import load_scenario
from engine.scenario.world import World
from engine.sim.camera import SimulatedCamera
from engine.vision.preprocess import Preprocessing, crop

WINDOW = (slice(116, 244), slice(256, 384))  # the centred 128 x 128 window of 640 x 360


def scenario_file(tmp_path: Path, events: str, duration_s: float = 10) -> Path:
    path = tmp_path / "scene.yaml"
    path.write_text(f"duration_s: {duration_s}\nevents:\n" + textwrap.dedent(events))
    return path


def camera_on(tmp_path: Path, events: str) -> tuple[SimulatedCamera, ScenarioPlayer, VirtualClock]:
    clock = VirtualClock()
    world = World()
    camera = SimulatedCamera(world, clock)
    world.add_listener(camera)
    player = ScenarioPlayer(load_scenario(scenario_file(tmp_path, events)), world)
    camera.open()
    return camera, player, clock


def at(player: ScenarioPlayer, clock: VirtualClock, seconds: float) -> None:
    clock.advance(seconds - clock.now())
    player.advance_to(clock.now())


def test_a_person_holding_up_fingers_is_in_view_while_it_lasts(tmp_path: Path) -> None:
    camera, player, clock = camera_on(
        tmp_path, "  - {at: 1.0, show_hand: {fingers: 3, seconds: 2}}\n"
    )
    room = camera.read()
    assert room.shape == (360, 640, 3)
    at(player, clock, 1.5)
    held = camera.read()
    assert np.abs(held[WINDOW].astype(int) - room[WINDOW].astype(int)).mean() > 10
    assert np.array_equal(camera.read(), held)  # a still hand: the same pose each frame
    at(player, clock, 3.5)
    assert np.array_equal(camera.read(), room)


def test_a_person_holding_up_three_fingers_is_counted_three(tmp_path: Path) -> None:
    """``fingers: 3`` is a real webcam frame of a person holding up three fingers at arm's
    length (examples/hands-arms-length), which the robot's hand finder counts."""
    from engine.vision.hand_finder import HandFinder

    camera, player, clock = camera_on(
        tmp_path, "  - {at: 1.0, show_hand: {fingers: 3, seconds: 2}}\n"
    )
    at(player, clock, 1.5)
    reading = HandFinder.load().read(camera.read())
    assert reading.present and reading.fingers == 3


def test_a_picture_held_at_a_distance_is_placed_and_scaled_in_the_room(tmp_path: Path) -> None:
    photo = np.zeros((100, 100, 3), np.uint8)
    photo[:, :, 1] = 180  # green
    cv2.imwrite(str(tmp_path / "hand.png"), photo)
    events = "  - {at: 1.0, show_hand: {image: hand.png, at: [300, 50], width_px: 50}}\n"
    camera, player, clock = camera_on(tmp_path, events)
    room = camera.read()
    at(player, clock, 1.0)
    frame = camera.read()
    assert (frame[50:100, 300:350, 1] == 180).all() and (frame[50:100, 300:350, 0] == 0).all()
    assert np.array_equal(frame[100:, :], room[100:, :])  # the room around it is still there
    assert np.array_equal(frame[:, :300], room[:, :300])


def test_a_picture_bigger_than_the_frame_is_seen_whole(tmp_path: Path) -> None:
    picture = np.zeros((720, 1280, 3), np.uint8)
    picture[:, :, 2] = 200
    picture[:10, :10] = 255  # a white corner: still in view, scaled
    cv2.imwrite(str(tmp_path / "wide.png"), picture)
    camera, player, clock = camera_on(tmp_path, "  - {at: 1.0, show_hand: {image: wide.png}}\n")
    at(player, clock, 1.0)
    frame = camera.read()
    assert frame.shape == (360, 640, 3) and frame[1, 1].min() > 200 and frame[200, 400, 2] == 200


def test_a_picture_is_placed_in_the_frame_unscaled(tmp_path: Path) -> None:
    picture = np.zeros((128, 128, 3), np.uint8)
    picture[:, :, 2] = 200  # red
    cv2.imwrite(str(tmp_path / "red.png"), picture)
    camera, player, clock = camera_on(tmp_path, "  - {at: 1.0, show_hand: {image: red.png}}\n")
    at(player, clock, 1.0)
    frame = camera.read()
    assert (frame[WINDOW][:, :, 2] == 200).all() and (frame[WINDOW][:, :, 0] == 0).all()


def test_a_photograph_smaller_than_the_window_is_held_up_close_to_fill_it(
    tmp_path: Path,
) -> None:
    """A 100 x 100 px photograph of a hand would sit in the window with the room around it;
    held up close, it fills the window, as `vest gesture` reads such a picture."""
    photo = np.zeros((100, 100, 3), np.uint8)
    photo[:, :, 1] = 180  # green
    cv2.imwrite(str(tmp_path / "hand.png"), photo)
    camera, player, clock = camera_on(tmp_path, "  - {at: 1.0, show_hand: {image: hand.png}}\n")
    room = camera.read()
    at(player, clock, 1.0)
    frame = camera.read()
    assert (frame[WINDOW][:, :, 1] == 180).all() and (frame[WINDOW][:, :, 0] == 0).all()
    outside = (slice(0, 100), slice(0, 200))
    assert np.array_equal(frame[outside], room[outside])  # the room around it is still there


def test_the_camera_holds_up_a_small_picture_as_vest_gesture_reads_it(tmp_path: Path) -> None:
    """A narrow photograph (60 x 100 px): the camera shows the window `vest gesture` reads,
    so a scenario and the command count the same picture alike."""
    rng = np.random.default_rng(4)
    photo = rng.integers(0, 255, size=(100, 60, 3)).astype(np.uint8)
    cv2.imwrite(str(tmp_path / "narrow.png"), photo)
    camera, player, clock = camera_on(tmp_path, "  - {at: 1.0, show_hand: {image: narrow.png}}\n")
    at(player, clock, 1.0)
    assert np.array_equal(camera.read()[WINDOW], crop(photo, Preprocessing()))


def test_a_video_plays_on_the_robot_s_clock_from_when_it_is_shown(tmp_path: Path) -> None:
    video = tmp_path / "clip.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter.fourcc(*"MJPG"), 10.0, (640, 360))
    for level in (0, 60, 120, 180, 240):
        writer.write(np.full((360, 640, 3), level, np.uint8))
    writer.release()
    camera, player, clock = camera_on(
        tmp_path, "  - {at: 2.0, show_hand: {video: clip.avi, seconds: 5}}\n"
    )
    levels = []
    for second in (2.0, 2.1, 2.25, 2.45, 4.0):
        at(player, clock, second)
        levels.append(round(float(camera.read().mean()), -1))
    assert levels == [0, 60, 120, 240, 240]  # 10 fps; after its end, its last frame


def test_an_unplugged_camera_gives_no_frames_until_it_is_back(tmp_path: Path) -> None:
    camera, player, clock = camera_on(
        tmp_path, "  - {at: 1.0, unplug: {device: camera, seconds: 2}}\n"
    )
    at(player, clock, 1.0)
    with pytest.raises(CameraError, match="unplugged"):
        camera.read()
    with pytest.raises(CameraError, match="cannot be opened"):
        camera.open()
    at(player, clock, 3.0)
    camera.open()
    assert camera.read().shape == (360, 640, 3)


def problems(tmp_path: Path, events: str) -> list[str]:
    with pytest.raises(LoadError) as caught:
        load_scenario(scenario_file(tmp_path, events), "scene.yaml")
    return [str(problem) for problem in caught.value.problems]


def test_a_place_without_a_size_is_named(tmp_path: Path) -> None:
    (tmp_path / "hand.png").write_bytes(cv2.imencode(".png", np.zeros((9, 9, 3), np.uint8))[1])
    [problem] = problems(tmp_path, "  - {at: 1.0, show_hand: {image: hand.png, at: [1, 2]}}\n")
    assert "at and width_px go together" in problem
    [problem] = problems(tmp_path, "  - {at: 1.0, show_hand: {fingers: 2, width_px: 40}}\n")
    assert "at and width_px place a picture" in problem


def test_show_hand_takes_one_thing_to_show(tmp_path: Path) -> None:
    [problem] = problems(tmp_path, "  - {at: 1.0, show_hand: {fingers: 2, image: a.png}}\n")
    assert problem.startswith("scene.yaml:3:")
    assert "show_hand takes one of fingers, image and video" in problem


def test_a_count_beyond_a_hand_is_named(tmp_path: Path) -> None:
    [problem] = problems(tmp_path, "  - {at: 1.0, show_hand: {fingers: 6}}\n")
    assert "scene.yaml:3:" in problem and "'fingers'" in problem and "5" in problem


def test_a_missing_picture_and_a_file_that_is_no_video_are_named_before_the_run(
    tmp_path: Path,
) -> None:
    (tmp_path / "notes.avi").write_text("not a video")
    found = problems(
        tmp_path,
        "  - {at: 1.0, show_hand: {image: gone.png}}\n"
        "  - {at: 2.0, show_hand: {video: notes.avi}}\n",
    )
    assert len(found) == 2
    assert "scene.yaml:3:" in found[0] and "gone.png: no such file" in found[0]
    assert "scene.yaml:4:" in found[1] and "notes.avi: not a video OpenCV can play" in found[1]


def test_a_fifo_or_a_folder_shown_to_the_camera_is_named_and_never_waited_on(
    tmp_path: Path,
) -> None:
    os.mkfifo(tmp_path / "pipe.avi")
    (tmp_path / "pictures").mkdir()
    found = problems(
        tmp_path,
        "  - {at: 1.0, show_hand: {video: pipe.avi}}\n"
        "  - {at: 2.0, show_hand: {image: pictures}}\n",
    )
    assert "pipe.avi: is not a regular file; name a video file" in found[0]
    assert "pictures: is not a regular file; name a picture file" in found[1]


def test_a_hand_held_up_while_another_is_lowered_stays(tmp_path: Path) -> None:
    camera, player, clock = camera_on(
        tmp_path,
        "  - {at: 1.0, show_hand: {fingers: 2, seconds: 5}}\n"
        "  - {at: 3.0, show_hand: {fingers: 4, seconds: 5}}\n",
    )
    room = camera.read()
    at(player, clock, 6.5)  # the first is lowered at 6 s; the second is still up
    assert not np.array_equal(camera.read()[WINDOW], room[WINDOW])
    at(player, clock, 8.5)
    assert np.array_equal(camera.read(), room)

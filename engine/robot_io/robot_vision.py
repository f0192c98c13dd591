"""The robot's sight, built from its config's ``camera:`` section.

The camera (a webcam through OpenCV, or the simulated vest's camera looking at the
simulated world), the hand finder (MediaPipe's palm detector and hand landmarks, with the
paper's network, named there, for close-ups) and the vision worker that joins them. A
model that is missing or broken is said once, clearly, at start-up, and the robot runs
without counting fingers (``/devices/camera/ok`` stays False); the rest of the robot is
not held up by its eyes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from engine.blackboard.board import Blackboard
from engine.clock import Clock
from engine.errors import ConfigError
from engine.hardware.config import CAMERA_NAME, CameraConfig
from engine.hardware.device_health import DeviceHealth
from engine.media.camera import Camera, OpenCvCamera
from engine.robot_io.hand_watcher import HandWatcher
from engine.scenario.world import World
from engine.sim.camera import SimulatedCamera
from engine.vision.classifier import DEFAULT_MODEL, HandModel
from engine.vision.hand_finder import HandFinder


@dataclass
class RobotVision:
    """The camera, its health, and the worker (None when the model could not be loaded:
    ``problem`` says why)."""

    camera: Camera
    health: DeviceHealth
    watcher: HandWatcher | None
    problem: str | None = None
    _closed: bool = field(default=False, init=False)

    def start(self) -> None:
        """On a real clock: start the worker thread."""
        if self.watcher is not None:
            self.watcher.start()

    def close(self) -> None:
        """Stop the worker and close the camera (once; again does nothing)."""
        if self._closed:
            return
        self._closed = True
        if self.watcher is not None:
            self.watcher.stop()
        else:
            self.camera.close()


def load_hand_model(config: CameraConfig) -> HandModel:
    """The config's model (the project's by default), reading the config's window when it
    names one (else the model's own); ConfigError naming the file."""
    model = HandModel.load(
        config.model or DEFAULT_MODEL,
        threads=config.threads,
        providers=config.providers,
        min_confidence=config.min_confidence,
    )
    if config.crop is not None:
        model.settings = model.settings.with_crop(*config.crop)
    return model


def open_camera(
    config: CameraConfig, world: World, clock: Clock, *, window: tuple[int, int] | None
) -> Camera:
    """The config's camera, not yet opened; the simulated one listens to ``world`` and
    draws a hand in the ``window`` (its top-left corner, px; None: centred)."""
    if config.simulated:
        camera = SimulatedCamera(
            world,
            clock,
            width=config.width,
            height=config.height,
            window=window,
            name=CAMERA_NAME,
        )
        world.add_listener(camera)
        return camera
    return OpenCvCamera(config.device, width=config.width, height=config.height, fps=config.fps)


def build_vision(
    config: CameraConfig, world: World, clock: Clock, blackboard: Blackboard
) -> RobotVision:
    """The robot's sight; never raises for a bad model (see the module's doc)."""
    health = DeviceHealth(CAMERA_NAME, blackboard)
    try:
        model = HandFinder.load(threads=config.threads, close_ups=load_hand_model(config))
    except ConfigError as error:
        problem = f"{error}; the robot runs without counting fingers"
        health.driver_status(False, problem)  # the caller says it (vest run: at start-up)
        camera = open_camera(config, world, clock, window=config.crop)
        return RobotVision(camera, health, None, problem)
    try:  # the simulated camera holds a close-up where the paper's network looks
        assert model.close_ups is not None
        window: tuple[int, int] | None = model.close_ups.settings.window(
            config.height, config.width
        )
    except ValueError:
        window = None
    camera = open_camera(config, world, clock, window=window)
    watcher = HandWatcher(
        camera,
        model,
        blackboard,
        clock,
        health,
        fps=config.fps,
        steady_frames=config.steady_frames,
    )
    return RobotVision(camera, health, watcher)

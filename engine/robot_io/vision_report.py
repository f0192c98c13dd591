"""``vest devices`` rows for the camera and the hand model: the camera opened and one frame
read; the model loaded, its input shape, the providers it runs on, and one inference."""

from __future__ import annotations

from engine.clock import Clock, RealClock
from engine.errors import ConfigError
from engine.hardware.config import CAMERA_NAME, CameraConfig
from engine.hardware.device_report import DeviceRow
from engine.media.camera import CameraError
from engine.media.images import Frame
from engine.robot_io.robot_vision import load_hand_model, open_camera
from engine.scenario.world import World


def describe_vision(config: CameraConfig, clock: Clock) -> list[DeviceRow]:
    """One row for the camera, one for the model (run once on the camera's frame)."""
    where = "simulated vest" if config.simulated else str(config.device)
    camera = open_camera(config, World(), clock, window=config.crop)
    frame: Frame | None = None
    try:
        camera.open()
        frame = camera.read()
    except CameraError as error:
        rows = [DeviceRow(CAMERA_NAME, "webcam (OpenCV)", where, False, f"no: {error}", "-")]
    else:
        height, width = frame.shape[:2]
        rows = [
            DeviceRow(
                CAMERA_NAME,
                "webcam (OpenCV)",
                where,
                True,
                f"{width}x{height} px",
                f"asked {config.width}x{config.height} at {config.fps:g} fps",
            )
        ]
    finally:
        camera.close()
    rows.append(_model_row(config, frame))
    return rows


def _model_row(config: CameraConfig, frame: Frame | None) -> DeviceRow:
    name = "hand model"
    try:
        model = load_hand_model(config)
    except ConfigError as error:
        where = str(config.model or "default")
        return DeviceRow(name, "CNN (ONNX)", where, False, f"no: {error}", "-")
    shape = "x".join(str(n) for n in model.session.get_inputs()[0].shape)
    providers = ", ".join(p.removesuffix("ExecutionProvider") for p in model.providers)
    identity = f"input {shape}, on {providers}"
    if frame is None:
        return DeviceRow(name, "CNN (ONNX)", model.path.name, True, identity, "no frame to read")
    stopwatch = RealClock()  # how long it took on this machine, whatever the robot's clock
    started = stopwatch.now()
    try:
        reading = model.read(frame)
    except ValueError as error:  # the camera's frames do not hold the window
        return DeviceRow(name, "CNN (ONNX)", model.path.name, False, f"no: {error}", "-")
    took_ms = (stopwatch.now() - started) * 1000
    said = "not sure" if reading.fingers is None else f"{reading.fingers} fingers"
    return DeviceRow(
        name,
        "CNN (ONNX)",
        model.path.name,
        True,
        identity,
        f"{said} ({reading.confidence:.0%}) in {took_ms:.1f} ms",
    )

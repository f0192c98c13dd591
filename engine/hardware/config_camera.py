"""The ``camera:`` section of a robot config: the webcam and the hand model it feeds.

::

    camera:
      device: 0                 # an index (/dev/video0) or a path; the simulated vest's
                                # camera when the vest is simulated and this is left out
      width: 640                # px, as the paper's webcam (640 x 360)
      height: 360
      fps: 15                   # frames a second asked of the camera
      crop: center              # the 128 x 128 window: center, or [x, y] (its top-left, px)
      model: default            # the project's model, or a .onnx file (its .json beside it)
      threads: 1                # ONNX Runtime threads for the network
      providers: auto           # or a list, e.g. [CUDAExecutionProvider, CPUExecutionProvider]
      min_confidence: 0.6       # below it a frame reads as "not sure" (no count)
      steady_frames: 3          # frames a count must hold before it is an event

A simulated vest has a simulated camera unless ``camera: none``; a robot has none unless
the section names one.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from engine.files.yaml_source import YMap, YValue, plain
from engine.hardware.chips.fields import ConfigChecks
from engine.hardware.config import SIMULATED_CAMERA, CameraConfig
from engine.values.params import Integer, Number, Param, Text

OWN_CHECKS = ("device", "crop", "providers")
"""Fields checked here rather than by a parameter type (they take more than one shape)."""
FIELDS: tuple[Param[Any], ...] = (
    Param("width", Integer(32, 7680), 640, "frame width, px"),
    Param("height", Integer(32, 4320), 360, "frame height, px"),
    Param("fps", Number(0.5, 240.0, "Hz"), 15.0, "frames a second"),
    Param("model", Text(), "default", "default, or a .onnx file"),
    Param("threads", Integer(1, 64), 1, "ONNX Runtime threads"),
    Param("min_confidence", Number(0.0, 1.0), 0.6, "below it: not sure"),
    Param("steady_frames", Integer(1, 100), 3, "frames a count must hold"),
)
PROVIDERS = ("TensorrtExecutionProvider", "CUDAExecutionProvider", "CPUExecutionProvider")


def check_camera(
    checker: ConfigChecks, document: YMap, simulated: bool, folder: Path
) -> CameraConfig | None:
    """The camera, or None for none. Paths are relative to the config's ``folder``."""
    raw = document.get("camera")
    if raw is None:
        return CameraConfig() if simulated else None
    if plain(raw) in ("none", None):
        return None
    section = checker.mapping(raw, "'camera'", "e.g. camera: {device: 0, fps: 15}")
    if section is None:
        return None
    checker.unknown_fields(section, [*OWN_CHECKS, *(p.name for p in FIELDS)], "camera")
    entries = {key: value for key, value in section.items() if key not in OWN_CHECKS}
    values = checker.fields(YMap(entries, section.mark, section.key_marks), FIELDS, "camera")
    if values is None:  # named; the other fields are still checked, on the defaults
        values = {param.name: param.default for param in FIELDS}
    config = CameraConfig(
        device=_device(checker, section, simulated),
        width=values["width"],
        height=values["height"],
        fps=values["fps"],
        crop=_crop(checker, section.get("crop")),
        model=None if values["model"] == "default" else folder / values["model"],
        threads=values["threads"],
        providers=_providers(checker, section.get("providers")),
        min_confidence=values["min_confidence"],
        steady_frames=values["steady_frames"],
    )
    side = 128
    if config.crop is not None and (
        config.crop[0] + side > config.width or config.crop[1] + side > config.height
    ):
        checker.problems.add(
            section.entries["crop"].mark,
            f"the {side}x{side} window at {list(config.crop)} does not fit a "
            f"{config.width}x{config.height} frame",
            "move it, or use crop: center",
        )
    if config.width < side or config.height < side:
        checker.problems.add(
            section.mark, f"frames must be at least {side}x{side} px (the network's window)"
        )
    return config


def _device(checker: ConfigChecks, section: YMap, simulated: bool) -> int | str:
    raw = section.get("device")
    if raw is None:
        if simulated:
            return SIMULATED_CAMERA
        checker.problems.add(
            section.mark, "camera needs 'device' on a robot", "e.g. device: 0 or /dev/video0"
        )
        return SIMULATED_CAMERA
    value = plain(raw)
    if isinstance(value, int) and not isinstance(value, bool) and 0 <= value < 64:
        return value
    if isinstance(value, str) and value.strip() == value and value:
        if value == SIMULATED_CAMERA and not simulated:
            checker.problems.add(
                raw.mark, "the simulated camera needs a simulated vest", "e.g. device: 0"
            )
        return value
    checker.problems.add(
        raw.mark, f"camera 'device' must be an index 0..63 or a path, got {value!r}"
    )
    return SIMULATED_CAMERA


def _crop(checker: ConfigChecks, raw: YValue | None) -> tuple[int, int] | None:
    value = None if raw is None else plain(raw)
    if value in (None, "center"):
        return None
    if (
        isinstance(value, list)
        and len(value) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) and v >= 0 for v in value)
    ):
        return int(value[0]), int(value[1])
    assert raw is not None
    checker.problems.add(
        raw.mark, f"camera 'crop' must be center or [x, y] in px, got {value!r}", "e.g. [256, 116]"
    )
    return None


def _providers(checker: ConfigChecks, raw: YValue | None) -> tuple[str, ...] | None:
    value = None if raw is None else plain(raw)
    if value in (None, "auto"):
        return None
    if isinstance(value, list) and value and all(v in PROVIDERS for v in value):
        return tuple(value)
    assert raw is not None
    checker.problems.add(
        raw.mark,
        f"camera 'providers' must be auto or a list of {', '.join(PROVIDERS)}, got {value!r}",
    )
    return None

"""List the robot's configured devices, probe each, and show its identity and one reading;
then the camera and the hand model (one frame through the network), the sound devices
and the speech models (each loaded once: a few seconds).

On the simulated vest (the default config) it works the same as on the robot: the real
drivers talk to register-level chip models. Exits 1 when a device does not answer as the
chip it should be.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from engine.clock import Clock, RealClock, VirtualClock
from engine.hardware.assembly import build_hardware
from engine.hardware.config_file import load_robot_config
from engine.hardware.device_report import describe_devices, format_rows
from engine.hardware.sim_vest import build_sim_vest
from engine.scenario.world import World

# the MCP9808's first conversion takes 250 ms; a simulated vest is given that long first
SIMULATED_WARM_UP_S = 0.3


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--hardware",
        type=Path,
        default=Path("examples/robots/sim.yaml"),
        metavar="CONFIG",
        help="robot config (default: examples/robots/sim.yaml, the simulated vest)",
    )
    parser.add_argument(
        "--no-camera", action="store_true", help="leave out the camera and the hand model"
    )
    parser.add_argument(
        "--no-speech", action="store_true", help="leave out the sound devices and speech models"
    )


def main(args: argparse.Namespace) -> int:
    config = load_robot_config(args.hardware)
    clock: Clock = VirtualClock() if config.simulated else RealClock()
    vest = build_sim_vest(config, World(), clock) if config.simulated else None
    hardware = build_hardware(config, clock, None, vest=vest)
    try:
        if vest is not None:
            vest.clock.sleep(SIMULATED_WARM_UP_S)
        rows = describe_devices(hardware)
        if config.camera is not None and not args.no_camera:
            from engine.robot_io.vision_report import describe_vision

            rows += describe_vision(config.camera, clock)
        if not args.no_speech:
            from engine.robot_io.speech_report import describe_speech

            rows += describe_speech(config.audio, config.simulated)
    finally:
        hardware.close()
        if vest is not None:
            vest.close()
    print(format_rows(rows))
    failing = [row.name for row in rows if not row.ok]
    if failing:
        print(f"{len(failing)} device(s) not answering: {', '.join(failing)}")
        return 1
    return 0

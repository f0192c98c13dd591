"""One factory builds the robot: `vest run`, the tests and the benchmarks use it.

:func:`build_robot` wires what a robot config and the validated behaviors describe: one
blackboard (with the catalogue the trees were checked against), the world a simulated vest
answers to, the bus managers, drivers, pollers and hardware services, and the trees on a
scheduler whose hooks poll the devices, and the camera's vision worker when the config
has a camera. Every speech, LED and servo call passes through the config's safety envelope,
whose watcher stops the arms between ticks when a person is too close or presses too hard.
The caller hands in the speech (the assembled
:class:`~engine.speech.robot_speech.RobotSpeech`, or any Speech service, e.g. a recording
fake, with heard text then staged as text) and the cloud's service. The caller adds its
own hooks (a scenario player goes first: the world moves, then the pollers read it, then
the trees tick) and runs it.
"""

from __future__ import annotations

from dataclasses import dataclass

from engine.blackboard.board import Blackboard
from engine.clock import Clock
from engine.hardware.assembly import build_hardware
from engine.hardware.config import RobotConfig
from engine.hardware.robot_hardware import Hardware
from engine.hardware.safety_envelope import (
    EnvelopedServos,
    EnvelopeWatcher,
    SafetyEnvelope,
    with_envelope,
)
from engine.hardware.sim_vest import SimVest, UnwiredSenses, build_sim_vest
from engine.robot_io.robot_speech import RobotSpeech
from engine.robot_io.robot_vision import RobotVision, build_vision
from engine.runtime.robot import Behaviors, Robot
from engine.scenario.world import World
from engine.services.interfaces import IotResults, Services, Speech
from engine.session.stream import SessionStream


@dataclass
class AssembledRobot:
    """A robot built by :func:`build_robot`; :meth:`close` releases what it opened."""

    robot: Robot
    clock: Clock
    blackboard: Blackboard
    world: World
    hardware: Hardware
    vest: SimVest | None
    speech: RobotSpeech | None = None
    vision: RobotVision | None = None

    def start(self, origin_s: float) -> None:
        """Start the poller threads (real time), phased on the trees' first deadline (s),
        and the vision worker."""
        self.hardware.start(origin_s=origin_s)
        if self.vision is not None and self.hardware.threaded:
            self.vision.start()

    def close(self) -> None:
        """Stop the pollers, bus workers and the vision worker, close the buses, the camera
        and the simulated vest."""
        try:
            if self.speech is not None:
                self.speech.close()
            if self.vision is not None:
                self.vision.close()
            self.hardware.close()
        finally:
            if self.vest is not None:
                self.vest.close()


def build_robot(
    behaviors: Behaviors,
    config: RobotConfig,
    *,
    clock: Clock,
    speech: Speech | RobotSpeech,
    iot: IotResults,
    fallback: Services | None = None,
    session: SessionStream | None = None,
) -> AssembledRobot:
    """The robot of ``config`` running ``behaviors`` on ``clock``.

    ``config.simulated`` builds the register-level simulated vest behind the same buses;
    ``fallback`` serves what the config has no device for (e.g. simulated LEDs). What
    happens is published on ``session`` (a new stream when not given: ``robot.session``).
    """
    session = session or SessionStream(clock)
    blackboard = Blackboard(behaviors.loader.catalogue, clock)
    blackboard.reset()
    world = World()
    vest = build_sim_vest(config, world, clock) if config.simulated else None
    robot_speech = speech if isinstance(speech, RobotSpeech) else None
    if robot_speech is not None:
        robot_speech.hears_into(blackboard)
        world.listeners.append(robot_speech)
    heard_as_text = robot_speech is None or robot_speech.listener is None
    world.listeners.append(UnwiredSenses(blackboard, hear=heard_as_text))  # the cloud: no device
    hardware = build_hardware(config, clock, blackboard, vest=vest)
    try:
        service = robot_speech.speaker if robot_speech is not None else speech
        services = hardware.services(speech=service, iot=iot, fallback=fallback)  # type: ignore[arg-type]
        envelope = SafetyEnvelope.of(config, blackboard, session)
        services = with_envelope(services, envelope)  # no tree reaches around it
        robot = Robot(
            behaviors, clock=clock, services=services, blackboard=blackboard, session=session
        )
    except BaseException:
        hardware.close()
        if vest is not None:
            vest.close()
        raise
    robot.scheduler.hooks.extend(hardware.hooks)
    assert isinstance(services.servos, EnvelopedServos)
    robot.scheduler.hooks.append(EnvelopeWatcher(services.servos, envelope))
    if robot_speech is not None:  # the microphone hears the room the world just changed
        robot.scheduler.hooks.append(robot_speech)
    vision = None
    if config.camera is not None:  # the camera sees the world just changed, as the chips do
        vision = build_vision(config.camera, world, clock, blackboard)
        if vision.watcher is not None and not hardware.threaded:
            robot.scheduler.hooks.append(vision.watcher)
    return AssembledRobot(robot, clock, blackboard, world, hardware, vest, robot_speech, vision)

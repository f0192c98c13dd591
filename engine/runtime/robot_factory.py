"""One factory builds the robot: `vest run`, the tests and the benchmarks use it.

:func:`build_robot` wires what a robot config and the validated behaviors describe: one
blackboard (with the catalogue the trees were checked against), the world a simulated vest
answers to, the bus managers, drivers, pollers and hardware services, and the trees on a
scheduler whose hooks poll the devices, and the camera's vision worker when the config
has a camera. Every speech, LED and servo call passes through the config's safety envelope,
whose watcher stops the arms between ticks when a person is too close or presses too hard.
The caller hands in the Speech service the trees call and,
when the robot hears and speaks through the models, the assembled
:class:`~engine.robot_io.robot_speech.RobotSpeech` whose speaker that service is (without
it, e.g. a recording fake, heard text is staged as text), and the cloud's service. What
it opens is on the robot's :class:`~engine.runtime.lifecycle.Lifecycle`; the composition
root (:mod:`engine.composition.session_root`) adds every other part of a run around it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

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
from engine.runtime.lifecycle import Lifecycle
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
    lifecycle: Lifecycle = field(default_factory=Lifecycle)
    first_tick_s: float = 0.0
    """When the trees first tick (clock seconds): the pollers are phased on it."""
    _runners: bool = False

    def add_runners(self) -> None:
        """Put the poller threads (real time) and the camera's worker on the lifecycle, to
        start with it (once)."""
        if self._runners:
            return
        self._runners = True
        hardware, vision = self.hardware, self.vision
        self.lifecycle.add(
            "pollers", start=lambda: hardware.start(origin_s=self.first_tick_s), stop=hardware.stop
        )
        if vision is not None and hardware.threaded:
            self.lifecycle.add("camera's worker", start=vision.start, stop=vision.close)

    def start(self, origin_s: float) -> None:
        """Start the pollers, phased on the trees' first deadline ``origin_s`` (s), and the
        vision worker (for a robot run without the composition root: tests, benchmarks)."""
        self.first_tick_s = origin_s
        self.add_runners()
        self.lifecycle.start()

    def close(self) -> None:
        """Stop the speech, the vision worker, the pollers and bus workers, close the buses,
        the camera and the simulated vest (in that order: the reverse of their opening)."""
        self.lifecycle.stop()


def build_robot(
    behaviors: Behaviors,
    config: RobotConfig,
    *,
    clock: Clock,
    speech: Speech,
    iot: IotResults,
    robot_speech: RobotSpeech | None = None,
    fallback: Services | None = None,
    session: SessionStream | None = None,
) -> AssembledRobot:
    """The robot of ``config`` running ``behaviors`` on ``clock``, saying through
    ``speech`` (``robot_speech``'s speaker when it is given: it also hears).

    ``config.simulated`` builds the register-level simulated vest behind the same buses;
    ``fallback`` serves what the config has no device for (e.g. simulated LEDs). What
    happens is published on ``session`` (a new stream when not given: ``robot.session``).
    """
    session = session or SessionStream(clock)
    lifecycle = Lifecycle()
    blackboard = Blackboard(behaviors.loader.catalogue, clock)
    blackboard.reset()
    world = World()
    vest = build_sim_vest(config, world, clock) if config.simulated else None
    if vest is not None:
        lifecycle.add("simulated vest", stop=vest.close)
    if robot_speech is not None:
        lifecycle.add("speech", stop=robot_speech.close)
        robot_speech.hears_into(blackboard)
        world.add_listener(robot_speech)
    heard_as_text = robot_speech is None or robot_speech.listener is None
    world.add_listener(UnwiredSenses(blackboard, hear=heard_as_text))  # the cloud: no device
    try:
        hardware = build_hardware(config, clock, blackboard, vest=vest)
    except BaseException:
        lifecycle.stop()
        raise
    lifecycle.add("hardware", stop=hardware.close)
    try:
        services = hardware.services(speech=speech, iot=iot, fallback=fallback)
        envelope = SafetyEnvelope.of(config, blackboard, session)
        services = with_envelope(services, envelope)  # no tree reaches around it
        robot = Robot(
            behaviors, clock=clock, services=services, blackboard=blackboard, session=session
        )
    except BaseException:
        lifecycle.stop()
        raise
    for hook in hardware.hooks:
        robot.scheduler.add_hook(hook)
    assert isinstance(services.servos, EnvelopedServos)
    robot.scheduler.add_hook(EnvelopeWatcher(services.servos, envelope))
    if robot_speech is not None:  # the microphone hears the room the world just changed
        robot.scheduler.add_hook(robot_speech)
        robot_speech.on_interrupted = robot.spoken_over  # a person spoke over the robot
        robot_speech.on_person_speaks = robot.person_speaks  # the robot waits for them
    vision = None
    if config.camera is not None:  # the camera sees the world just changed, as the chips do
        try:
            vision = build_vision(config.camera, world, clock, blackboard)
        except BaseException:
            lifecycle.stop()
            raise
        lifecycle.add("camera", stop=vision.close)
        if vision.watcher is not None and not hardware.threaded:
            robot.scheduler.add_hook(vision.watcher)
    return AssembledRobot(
        robot, clock, blackboard, world, hardware, vest, robot_speech, vision, lifecycle
    )

"""The one place a running robot is built, every part included.

:func:`build_session` takes a :class:`SessionPlan` (what ``vest run``'s options, checked,
say, as data: the behaviors, the robot config, the scenario, the clock's kind, speech, the
cloud, the buttons, the live view, the recording) and builds the clock, the speech, the
cloud link and the robot with :func:`~engine.runtime.robot_factory.build_robot`, then
every part around it in the order
it must run: the scenario player first among the scheduler's hooks (the world moves, then
the pollers read it, then the trees tick), the buttons' tree and hook, the live view's hub
and server, the recorder, the reloader, the cloud link. Each part that runs beside the
trees is on the robot's one :class:`~engine.runtime.lifecycle.Lifecycle`:
:meth:`RunningSession.run` starts them in order and :meth:`RunningSession.close` stops
them in reverse.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

from engine.blackboard.catalogue import IOT_INBOX
from engine.buttons.acting import ActingNow
from engine.buttons.button_file import ButtonBoard
from engine.buttons.wizard import Wizard
from engine.clock import Clock, RealClock, VirtualClock
from engine.errors import ConfigError
from engine.hardware.config import RobotConfig
from engine.interop.ros2_plan import Ros2Plan
from engine.privacy.consent import Consent, without_record
from engine.privacy.consent_gate import ConsentGates
from engine.privacy.sealed_sqlite import Error as SealedError
from engine.privacy.site import Site
from engine.recording.recorder import SessionRecorder
from engine.robot_io.robot_speech import RobotSpeech
from engine.robot_io.speech_assembly import audio_folder, build_speech, speech_settings
from engine.runtime.reload import TreeReloader
from engine.runtime.robot import Behaviors
from engine.runtime.robot_factory import AssembledRobot, build_robot
from engine.scenario.player import ScenarioPlayer
from engine.scenario.scenario_file import Scenario, ScenarioEvent
from engine.services.cloud_link import CloudLink
from engine.services.simulated import simulated_services
from engine.session.events import WorldEvent
from engine.session.stream import SessionStream
from engine.view.cloud_session import SHOWN_KINDS, CloudSession
from engine.view.hub import ViewHub
from engine.view.server import LiveSource, ViewServer

if TYPE_CHECKING:
    from engine.interop.foxglove_live import FoxgloveLive
    from engine.interop.ros2_bridge import Ros2Bridge

log = logging.getLogger(__name__)
Part = TypeVar("Part")


@dataclass(frozen=True)
class ViewPlan:
    """The live view's address (port 0: any free one) and its token (None: a new one)."""

    host: str
    port: int
    token: str | None


@dataclass(frozen=True)
class RecordPlan:
    """A new recording at ``path``, sealed with ``site``'s key and put in its index."""

    path: Path
    site: Site


@dataclass(frozen=True)
class SpeechPlan:
    """Hear and speak through the speech models (the plan's ``speech`` None: hand the
    trees what is said as text, speak nothing); ``audio_out``: a WAV file per utterance
    there."""

    audio_out: Path | None = None


@dataclass(frozen=True)
class CloudPlan:
    """Take commands from the cloud service at ``url`` with the robot's ``token``; the
    finished commands are kept in ``done_file``."""

    url: str
    token: str
    done_file: Path


@dataclass(frozen=True)
class SessionPlan:
    """Everything a run is built from, as data. ``fast``: a virtual clock (as fast as the
    machine allows, no hot reload), else real time with hot reload; ``record``: the new
    recording's path, and ``facts`` (robot config, profile, scenario, person...)."""

    behaviors: Behaviors
    config: RobotConfig
    scenario: Scenario
    fast: bool = False
    speech: SpeechPlan | None = None
    cloud: CloudPlan | None = None
    buttons: ButtonBoard | None = None
    view: ViewPlan | None = None
    on_view_up: Callable[[ViewServer], None] | None = None
    """Told once the view serves (to say its address: a page opened then misses nothing)."""
    record: RecordPlan | None = None
    facts: Mapping[str, str] = field(default_factory=dict)
    consent: Consent = field(default_factory=lambda: without_record(""))
    """What the person (``consent.person``; '' for none) agreed may be kept and sent: what
    is recorded, and whether sensor readings go to the cloud as telemetry."""
    foxglove_port: int | None = None
    """Serve the session to Foxglove and Lichtblick on this loopback port (0: any free one)."""
    foxglove_origins: tuple[str, ...] = ()
    """Other sites' pages that may connect to it (with its token): Foxglove's web app."""
    on_foxglove_up: Callable[[FoxgloveLive], None] | None = None
    """Told once Foxglove's server listens (to say its address)."""
    ros2: Ros2Plan | None = None
    """Join this ROS 2 graph (publish the session; take commands when it says so)."""
    on_ros2_up: Callable[[Ros2Bridge], None] | None = None
    """Told once the robot is on the graph."""
    on_progress: Callable[[str], None] | None = None
    """Told what is being built before a slow part (the speech models load for seconds,
    up to a minute the first time), so a person is never left waiting in silence."""


@dataclass
class RunningSession:
    """A robot built by :func:`build_session`, with what runs beside it. Every reader of
    the session reads one of the consent gate's exits (``gates.kept``: the site's disks
    and screens; ``gates.sent``: off the robot), never the robot's own stream."""

    assembled: AssembledRobot
    start_s: float
    gates: ConsentGates
    wizard: Wizard | None = None
    view: ViewServer | None = None
    recorder: SessionRecorder | None = None
    foxglove: FoxgloveLive | None = None
    """Foxglove's live server, when asked for (its URL for the terminal)."""
    ros2: Ros2Bridge | None = None
    """The robot's node on a ROS 2 graph, when asked for."""

    def run(self, until_s: float) -> None:
        """Start every part in order, then tick the trees until ``until_s`` (clock
        seconds) or a stop. The first tick is due when the session begins, after the parts
        that come before it (pages, recorder, reloader) are up; the pollers and the camera
        are phased on it."""
        self.assembled.lifecycle.start()
        robot = self.assembled.robot
        try:
            robot.scheduler.run(until_s=until_s, start_s=self.assembled.first_tick_s)
        finally:  # commands that came too late are told, before the cloud link stops
            robot.refuse_commands(robot.trees, "the session ended")

    def close(self) -> None:
        """Stop every part, last started first (the robot's buses and the vest at the end)."""
        self.assembled.lifecycle.stop()


def build_session(plan: SessionPlan) -> RunningSession:
    """The robot of ``plan`` with every part it asks for, built but not yet running.

    A part that cannot be made (the view's port taken, say) closes what was built and
    raises: nothing is left open."""
    clock: Clock = VirtualClock() if plan.fast else RealClock()
    simulated = simulated_services(clock, realistic=True)
    robot_speech = _robot_speech(plan, clock)
    link = _cloud_link(plan.cloud, clock)
    assembled = build_robot(
        plan.behaviors,
        plan.config,
        clock=clock,
        speech=robot_speech.speaker if robot_speech is not None else simulated.speech,
        robot_speech=robot_speech,
        iot=link if link is not None else simulated.iot,
        fallback=simulated,  # what the config has no device for
    )
    try:
        return _around(assembled, plan, link)
    except BaseException:
        assembled.lifecycle.stop()
        raise


def _robot_speech(plan: SessionPlan, clock: Clock) -> RobotSpeech | None:
    """The speech models' voice and ears (None: speech as text), with the scenario's
    lines synthesized before the run."""
    if plan.speech is None:
        return None
    _progress(plan, "loading the speech models (the voice, the recognizer): up to a minute")
    audio_out = plan.speech.audio_out
    speech = build_speech(
        plan.config.audio,
        clock,
        simulated=plan.config.simulated,
        phrases=plan.behaviors.dialogs.phrases(),
        settle=plan.fast,
        on_utterance=audio_folder(audio_out) if audio_out is not None else None,
        **speech_settings(plan.behaviors.loader.profile),
    )
    for event in plan.scenario.events:
        if event.kind == "hear" and event.value["wav"] is None:
            speech.prepare(event.value["text"])
    return speech


def _progress(plan: SessionPlan, what: str) -> None:
    if plan.on_progress is not None:
        plan.on_progress(what)


def _cloud_link(cloud: CloudPlan | None, clock: Clock) -> CloudLink | None:
    if cloud is None:
        return None
    return CloudLink(cloud.url, cloud.token, clock, done_file=cloud.done_file)


def _around(assembled: AssembledRobot, plan: SessionPlan, link: CloudLink | None) -> RunningSession:
    robot, session, lifecycle = assembled.robot, assembled.robot.session, assembled.lifecycle
    clock = assembled.clock
    start_s = clock.now()  # after start-up, which takes simulated time too
    gates = ConsentGates(session, plan.consent)  # the one gate; every reader is behind it
    running = RunningSession(assembled, start_s, gates)
    if plan.buttons is not None:  # priority 100: ticks before the behaviors
        running.wizard = Wizard(plan.buttons, robot)
        robot.scheduler.add_hook(running.wizard)
        assembled.world.add_listener(running.wizard)
    player = ScenarioPlayer(
        plan.scenario, assembled.world, start_s=start_s, on_event=_world_events(session)
    )
    robot.scheduler.add_hook(player, first=True)
    if plan.view is not None:
        hub = ViewHub(clock, device_stats=assembled.hardware.stats)
        hub.begin(start_s, robot.trees)
        gates.kept.subscribe(hub)
        robot.scheduler.add_hook(hub.stats_hook)
        view = ViewServer(
            LiveSource(hub),
            host=plan.view.host,
            port=plan.view.port,
            token=plan.view.token,
            wizard=running.wizard,
            acting=_acting(plan, player, clock),
        )
        running.view = view
        lifecycle.add("view", start=_telling(view.start, view, plan.on_view_up), stop=view.stop)
    if plan.record is not None:
        record, consent = plan.record, plan.consent
        recorder = SessionRecorder(record.path, clock, record.site.key)
        running.recorder = recorder

        def close_recording() -> None:
            recorder.close()
            if recorder.length_s is None:
                return
            try:
                record.site.session_ended(record.path, recorder.length_s)
            except (ConfigError, SealedError) as error:  # the recording itself is whole
                log.error("the site's index did not take the session's length: %s", error)

        lifecycle.add("recording", stop=close_recording)  # closed even if it never starts
        recorder.describe(
            **plan.facts,
            person=consent.person,
            kept=",".join(sorted(consent.covers)),
            left_out=gates.keeping.left_out(),
        )
        recorder.begin(start_s)
        record.site.session_started(
            record.path, consent.person, plan.facts.get("profile", ""), tuple(consent.covers)
        )
        gates.kept.subscribe(recorder)
    if plan.foxglove_port is not None:
        from engine.interop.foxglove_live import FoxgloveLive  # the foxglove extra

        started = float(plan.facts.get("started", "0") or 0)  # seconds since the epoch
        live = FoxgloveLive(
            "127.0.0.1",
            plan.foxglove_port,
            clock,
            started - start_s,
            origins=plan.foxglove_origins,
        )
        running.foxglove = live
        start_live = _telling(live.start, live, plan.on_foxglove_up)
        lifecycle.add("foxglove", start=start_live, stop=live.stop)
        gates.kept.subscribe(live)
    if plan.ros2 is not None:
        from engine.interop.ros2_bridge import Ros2Bridge  # the ros2 extra

        if plan.ros2.commands and not _takes_commands(plan.behaviors):
            raise ConfigError(
                "--ros2-commands: no tree carries commands out (the iot_command tree, "
                "trees/iot_command.yaml, reads /iot/inbox): add it to --trees"
            )

        started = float(plan.facts.get("started", "0") or 0)
        bridge = Ros2Bridge(
            plan.ros2, clock, started - start_s, gates.sending, assembled.blackboard.catalogue
        )
        running.ros2 = bridge

        def start_bridge() -> None:
            bridge.start(assembled.blackboard)

        lifecycle.add(
            "ros2", start=_telling(start_bridge, bridge, plan.on_ros2_up), stop=bridge.stop
        )
        gates.sent.subscribe(bridge)
    if not plan.fast:  # reload work runs beside the scheduler, swaps between ticks
        wizard_tree = running.wizard.tree if running.wizard is not None else None
        behaving = [tree for tree in robot.trees if tree is not wizard_tree]
        reloader = TreeReloader(plan.behaviors.loader, behaving, clock, session=session)
        robot.scheduler.add_hook(reloader)
        lifecycle.add("reloader", start=reloader.start, stop=reloader.stop)

    def begin() -> None:  # every reader hears of every tree; the first tick is due now
        assembled.first_tick_s = clock.now()
        robot.begin_session(start_s)

    lifecycle.add("session", start=begin, stop=_nothing)
    assembled.add_runners()  # the pollers and the camera, phased on the first tick
    if link is not None:
        cloud_hub = ViewHub(clock)  # the cloud's page: what may leave the robot, in words
        cloud_hub.begin(start_s, robot.trees)
        shown = CloudSession(cloud_hub, running.wizard)
        gates.sent.subscribe(shown, SHOWN_KINDS)  # from the start: it hears of every tree

        def start_link() -> None:
            link.bind(assembled.blackboard, gates.sent, gates.sending, shown)
            link.start()

        lifecycle.add("cloud link", start=start_link, stop=link.stop)
    return running


def _telling(
    start: Callable[[], None], part: Part, told: Callable[[Part], None] | None
) -> Callable[[], None]:
    """``start``, then ``told(part)`` once it is up (a server's address, said when it
    serves: a page opened then misses nothing)."""

    def start_and_tell() -> None:
        start()
        if told is not None:
            told(part)

    return start_and_tell


def _takes_commands(behaviors: Behaviors) -> bool:
    """Whether a tree reads the commands staged on /iot/inbox."""
    return any(
        IOT_INBOX in node.args.values()
        for definition in behaviors.trees
        for node in definition.root.walk()
    )


def _nothing() -> None:
    """A part with nothing to stop."""


def _acting(plan: SessionPlan, player: ScenarioPlayer, clock: Clock) -> ActingNow | None:
    """The buttons page's hand on a simulated vest, in real time: never where a real
    person may be sensed (real chips, a microphone, a real camera), nor at full speed."""
    if plan.fast or plan.config.senses_people:  # a real child may be there
        return None
    return ActingNow(player, clock, plan.config)


def _world_events(session: SessionStream) -> Callable[[float, ScenarioEvent], None]:
    """What a scenario makes happen, published as the world's events; a scenario's press
    is the therapist's, published by the buttons when they carry it out."""

    def publish(at_s: float, event: ScenarioEvent) -> None:
        if event.kind != "press":
            session.publish(WorldEvent(at_s, event.kind, event.describe(), event.value))

    return publish

"""Run the robot's behaviors on a scripted scenario and print what it does.

Without arguments: every tree in trees/ on examples/scenarios/demo.yaml, in real time,
through the simulated vest (examples/robots/sim.yaml): the scenario moves register-level
chip models that the real drivers read. --hardware CONFIG names a robot config; on a robot
(e.g. examples/robots/hbs2.yaml) the same drivers read the real chips.
Speech goes through the real models: a scenario's hear: is spoken into the simulated
room, heard by Silero VAD and the recognizer (Moonshine by default), and the answers
are synthesized (--audio-out DIR keeps a WAV per utterance, NNN-robot.wav, replacing
those of an earlier run, listed as written about --person: erased and purged with the
session); --speech text skips the models, hands the trees the text and gives each
spoken word 0.3 s.
--fast runs on a virtual clock as fast as the machine allows; --json prints the session
as JSON lines, one object per event the timeline tells: {"t": seconds, "event": "action",
"tree": name, "action": ..., "args": {...}}, and how actions ended, turns, safety, presses,
what was heard (docs/view-and-recordings.md lists them).
In real time, a changed tree file is reloaded between ticks (an invalid change keeps the
running tree); Ctrl-C or SIGTERM stops cleanly at any moment, start-up included. The
timeline never stops the robot: if it cannot be written (a full disk), that is said once
on stderr, the run goes on, and it exits 1.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from urllib.parse import urlsplit

from engine.cli.interop_options import add_interop_arguments, ros2_plan, tell_foxglove, tell_ros2
from engine.cli.output import shown, tell
from engine.cli.run_inputs import (
    DEFAULT_HARDWARE,
    RunInputs,
    button_warnings,
    default_buttons,
    found,
    load_run_inputs,
)
from engine.cli.site_access import open_site, pseudonym
from engine.cli.timeline import Timeline
from engine.cli.validate_command import turn_warnings
from engine.cli.view_options import add_view_arguments, tell_view, view_plan
from engine.clock import EpochClock
from engine.composition.session_root import (
    CloudPlan,
    RecordPlan,
    SessionPlan,
    SpeechPlan,
    build_session,
)
from engine.errors import ConfigError, UsageError
from engine.files.problems import LoadError
from engine.files.yaml_source import read_text
from engine.loader.tree_checks import counting_warnings, spoken_quote_warnings
from engine.privacy.consent import of_a_simulation
from engine.privacy.site import Site
from engine.recording.session_file import check_new
from engine.runtime.robot import Behaviors
from engine.scenario.scenario_file import Scenario
from engine.session.sentences import TOLD_KINDS
from engine.view.server import ViewServer


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--trees",
        type=Path,
        nargs="+",
        default=[Path("trees")],
        metavar="PATH",
        help="tree files or folders (default: trees/)",
    )
    parser.add_argument(
        "--dialogs", type=Path, default=None, help="dialogs folder (default: dialogs/)"
    )
    parser.add_argument(
        "--profile",
        default=None,
        help="a profile file, or a name in trees/profiles/ (child, adult)",
    )
    parser.add_argument(
        "--scenario",
        type=Path,
        default=None,
        help="scenario file (default: examples/scenarios/demo.yaml on the simulated vest; "
        "none on a real robot, or with --buttons in real time, which then run until Ctrl-C)",
    )
    parser.add_argument(
        "--duration",
        type=_positive_seconds,
        default=None,
        metavar="S",
        help="seconds to run (default: the scenario's duration_s)",
    )
    parser.add_argument(
        "--fast", action="store_true", help="virtual clock: run as fast as the machine allows"
    )
    parser.add_argument(
        "--json",
        action="store_true",
        help="the session as JSON lines: one object per event (action, outcome, turn, "
        "safety, press, heard...)",
    )
    parser.add_argument(
        "--speech",
        choices=("models", "text"),
        default="models",
        help="models: hear and speak through the real speech models (default); "
        "text: hand the trees what is said as text, speak nothing",
    )
    parser.add_argument(
        "--audio-out",
        type=Path,
        default=None,
        metavar="DIR",
        help="write what the robot says as a WAV file per utterance into DIR",
    )
    parser.add_argument(
        "--cloud", default=None, metavar="URL", help="take commands from the cloud service at URL"
    )
    parser.add_argument(
        "--token-file",
        type=Path,
        default=None,
        metavar="FILE",
        help="the robot's token for --cloud (finished commands are kept in FILE.done.json)",
    )
    add_view_arguments(parser)
    parser.add_argument(
        "--buttons",
        type=Path,
        default=None,
        metavar="FILE",
        help="the therapist's buttons (a YAML file; default trees/buttons/session.yaml, whose "
        "buttons a scenario may press): given, a page at /buttons on the view's address "
        "(--view-port, --view-host) whose presses take over from the behaviors",
    )
    parser.add_argument(
        "--record",
        type=Path,
        default=None,
        metavar="FILE",
        help="record the session (trees, statuses, blackboard, actions) for vest replay",
    )
    parser.add_argument(
        "--person",
        type=pseudonym,
        default=None,
        metavar="PSEUDONYM",
        help="whose session this is, by pseudonym (e.g. kid-17; never a name): their consent "
        "record decides what is recorded and sent to the cloud; the session is listed under "
        "them (vest data list)",
    )
    add_interop_arguments(parser)
    parser.add_argument(
        "--hardware",
        type=Path,
        default=DEFAULT_HARDWARE,
        metavar="CONFIG",
        help="robot config (default: examples/robots/sim.yaml, the simulated vest)",
    )


def _profile_name(behaviors: Behaviors) -> str:
    profile = behaviors.loader.profile
    return "" if profile is None else str(profile.path or profile.name)


def _tell_progress(what: str) -> None:
    tell(f"vest run: {what}...")


def _positive_seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number of seconds, got {text!r}") from None
    if not 0 < value <= 7 * 24 * 3600:
        raise argparse.ArgumentTypeError(f"must be above 0 and at most a week, got {text}")
    return value


def _is_service_url(text: str) -> bool:
    """An http(s) URL with a host, and a port when one is given (1..65535)."""
    try:
        parts = urlsplit(text)
        port = parts.port
    except ValueError:  # [::1 unclosed, port 99999 or not a number
        return False
    return parts.scheme in ("http", "https") and bool(parts.hostname) and port != 0


def _cloud_plan(args: argparse.Namespace) -> CloudPlan | None:
    """The cloud for --cloud URL --token-file FILE; ConfigError or UsageError for what is
    wrong with them."""
    if args.cloud is None and args.token_file is None:
        return None
    if args.cloud is None or args.token_file is None:
        raise UsageError("--cloud URL and --token-file FILE go together")
    if not _is_service_url(args.cloud):
        raise UsageError(
            f"--cloud {args.cloud}: give the service's http:// or https:// URL "
            "(e.g. https://cloud.example.org or http://127.0.0.1:8080)"
        )
    if args.fast:
        raise UsageError("--cloud runs in real time: leave out --fast")
    try:
        token = read_text(
            args.token_file,
            max_bytes=4096,
            kind="token file",
            too_big_hint="it holds one line: the token `vest cloud add-robot` gave",
        ).strip()
    except LoadError as error:
        raise ConfigError(f"--token-file {error.problems[0]}") from None
    if not token or any(c.isspace() for c in token):
        raise ConfigError(f"--token-file {args.token_file}: holds no token (one line, no spaces)")
    done_file = args.token_file.with_name(args.token_file.name + ".done.json")
    return CloudPlan(args.cloud, token, done_file)


def main(args: argparse.Namespace) -> int:
    # the same checks as `vest validate`: every problem of every file, before anything starts
    if args.hardware == DEFAULT_HARDWARE:
        args.hardware = found(DEFAULT_HARDWARE)
        if not args.hardware.exists():
            raise ConfigError(
                f"no robot config: {DEFAULT_HARDWARE} is not here; run from the project "
                "folder, or give --hardware CONFIG"
            )
    inputs = load_run_inputs(
        args.trees,
        dialogs=args.dialogs,
        profile=args.profile,
        hardware=args.hardware,
        scenario=args.scenario,
        buttons=args.buttons or default_buttons(with_our_scenario=args.scenario is None),
    )
    config, scenario = inputs.config, inputs.scenario
    if args.fast and not config.simulated:
        raise ConfigError(f"{args.hardware}: --fast needs a simulated vest (simulated: true)")
    if args.buttons is not None and args.scenario is None and not args.fast:
        # only buttons asked for: a session the therapist leads, until Ctrl-C
        scenario = Scenario(duration_s=math.inf, events=(), path=Path("(the buttons alone)"))
        tell(
            "vest run: no scenario plays: the therapist's buttons lead the session "
            "(--scenario FILE plays one, e.g. examples/scenarios/demo.yaml)"
        )
    site = open_site()  # the key is made on first use
    try:
        return _run_for_site(args, site, inputs, scenario)
    finally:
        site.close()


def _run_for_site(
    args: argparse.Namespace, site: Site, inputs: RunInputs, scenario: Scenario
) -> int:
    behaviors, config = inputs.behaviors, inputs.config
    for erased in site.finish_erasures():
        tell(f"finished erasing {erased.person} (cut off earlier)")
    purged = site.purge()  # kept as long as the site said, no longer
    for entry in purged.sessions:
        tell(f"purged {entry.path} (older than {site.settings.keep_sessions_days:g} days)")
    for output in purged.outputs:
        tell(f"purged {output} (it held a purged session)")
    for path, why in purged.not_removed:
        tell(f"warning: could not remove {path} ({why}): it is past the site's keeping")
    consent = (
        site.consent_of(args.person)
        if args.person or config.senses_people
        else of_a_simulation()  # scripted on the simulated vest: nobody's data
    )
    if args.audio_out is not None and not consent.covers >= {"speech_text", "sensors"}:
        raise ConfigError(  # a Say may fill in what the person said, or a reading
            f"--audio-out {args.audio_out}: keeps the robot's every sentence, which may quote "
            f"what was heard or read; {consent.describe()}, so the files are not written "
            "(consent to speech_text and sensors allows them)"
        )
    if args.record is not None:
        check_new(args.record, site.key)  # before anything starts: never over a session
    if args.audio_out is not None and args.person:  # the robot's voice may quote them
        held = [args.record] if args.record is not None else []
        site.output_written(args.audio_out, args.person, "robot's voice", held)
    ros2 = ros2_plan(args, config.name)
    leaving = args.record is not None or args.cloud is not None or ros2 is not None
    if leaving or consent.left_out:  # what the timeline and the pages leave out, and why
        tell(f"privacy: {consent.describe()}")
    if args.person or args.record is not None:  # a session with someone: which settings
        profile = _profile_name(behaviors)
        used = f"profile {profile}" if profile else "the trees' own (no --profile)"
        tell(f"settings: {used}")
    cloud = _cloud_plan(args)
    paged = args.view or (args.buttons is not None and not args.fast)  # a page when asked
    duration = args.duration if args.duration is not None else scenario.duration_s

    def view_is_up(view: ViewServer) -> None:  # a page goes with the run: where, how long
        tell_view(view)
        tell(
            "the session runs until Ctrl-C"
            if math.isinf(duration)
            else f"the session lasts {duration:g} s (--duration S to change it), and "
            "the page with it"
        )

    running = build_session(
        SessionPlan(
            behaviors,
            config,
            scenario,
            fast=args.fast,
            speech=SpeechPlan(args.audio_out) if args.speech == "models" else None,
            cloud=cloud,
            buttons=inputs.buttons,
            view=view_plan(args) if paged else None,
            on_view_up=view_is_up,
            record=RecordPlan(args.record, site) if args.record is not None else None,
            consent=consent,
            facts={
                "robot_config": str(args.hardware),
                "profile": _profile_name(behaviors),
                "scenario": str(scenario.path),
                "started": f"{EpochClock().now():.3f}",
                "clock": "virtual" if args.fast else "real",
                "vest": "real" if config.senses_people else "simulated",
            },
            foxglove_port=args.foxglove,
            foxglove_origins=tuple(args.foxglove_origin),
            on_foxglove_up=tell_foxglove,
            ros2=ros2,
            on_ros2_up=tell_ros2,
            on_progress=_tell_progress,
        )
    )
    assembled = running.assembled
    robot = assembled.robot
    try:
        timeline = Timeline(sys.stdout, start_s=running.start_s, as_json=args.json)
        warnings = turn_warnings(behaviors.trees) + spoken_quote_warnings(behaviors.trees)
        warnings += counting_warnings(behaviors.trees)
        if inputs.buttons is not None and args.buttons is not None:  # the default: no noise
            warnings += button_warnings(inputs.buttons, [t.name for t in behaviors.trees])
        for warning in warnings:
            tell(warning)
        for name, why in assembled.hardware.startup_problems.items():
            tell(f"warning: {shown(name)} did not start ({shown(why)}); it will be tried again")
        if assembled.vision is not None and assembled.vision.problem:
            tell(f"warning: camera: {shown(assembled.vision.problem)}")
        if assembled.speech is not None:
            tell(f"speech: {assembled.speech.describe()}")
            for part, why in assembled.speech.problems.items():
                tell(f"warning: speech {part}: {shown(why)}")
        running.gates.kept.subscribe(timeline, TOLD_KINDS)  # behind the consent gate
        timeline.on_closed = robot.scheduler.stop
        # a signal that came during start-up stops the run before its first tick
        args.stop_signals.on_stop(robot.scheduler.stop)
        timeline.start()
        running.run(until_s=running.start_s + duration)
        timeline.summary(robot.trees)
    finally:
        running.close()
        recorder = running.recorder
        if recorder is not None:
            if recorder.stopped_why is None:
                tell(f"recording: {args.record} (vest replay {args.record} --view)")
            else:
                tell(
                    f"vest run: the recording {args.record} stopped before the session ended "
                    f"({recorder.stopped_why}); it holds what came before"
                )
    recorded = running.recorder is None or running.recorder.stopped_why is None
    return 0 if timeline.write_error is None and recorded else 1  # the robot ran; not its record

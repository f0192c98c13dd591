"""What ``vest run`` reads before the robot starts, checked as one: one set of checks.

Trees (with their subtrees and profile), the dialogs they use, the robot config and the
scenario are checked together, so a tree is checked against the robot it runs on: a key
``/devices/NAME/ok`` must name a configured device, ``item:`` must be inside the list the
robot's chip writes (the MPR121's 12 pads), a scenario may fail only devices the robot
has and send only remote commands the robot knows. ``vest run`` refuses to start on any
problem; ``vest validate`` runs these same functions and lists the same problems.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

from engine.blackboard.catalogue import KeyCatalogue, KeySpec, default_catalogue
from engine.buttons.button_file import BUTTONS_TREE, ButtonBoard, load_buttons
from engine.cli.robot_checks import check_on_robot, check_scenario_events, list_lengths
from engine.dialogs.library import DialogLibrary, find_dialogs_folder
from engine.errors import ConfigError
from engine.files.problems import LoadError, Problem, Problems
from engine.hardware.config import CAMERA_NAME, RobotConfig
from engine.hardware.config_file import load_robot_config
from engine.loader.tree_checks import variable_problems
from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_file import TreeLoader
from engine.nodes.registry import NodeRegistry, default_registry
from engine.runtime.robot import Behaviors, load_behaviors
from engine.scenario.scenario_file import Scenario, ScenarioEvent, load_scenario
from engine.values.param_problems import did_you_mean

PROJECT = Path(__file__).resolve().parents[2]
"""The folder vest was installed from (a checkout): its defaults are found from anywhere."""


def found(default: Path) -> Path:
    """A default file or folder of the project, looked for now: as named, where the command
    runs (the project folder, or one laid out like it), else the one in the project vest
    runs from, so ``vest validate`` and ``vest run`` find the simulated vest from any
    folder; as named when neither has it."""
    if default.exists() or default.is_absolute():
        return default
    there = PROJECT / default
    return there if there.exists() else default


DEFAULT_DIALOGS = Path("dialogs")
DEFAULT_HARDWARE = Path("examples/robots/sim.yaml")
DEFAULT_SCENARIO = Path("examples/scenarios/demo.yaml")
DEFAULT_BUTTONS = Path("trees/buttons/session.yaml")
_DEVICE_OK = "/devices/*/ok"


def default_buttons(*, with_our_scenario: bool = False) -> Path | None:
    """The button board a session gets when none is named: ``trees/buttons/session.yaml``
    where the command runs. The project vest runs from lends its board to a folder that is
    no project, or along with its demo scenario (``with_our_scenario``, which presses it); a
    project with trees/ of its own and no board otherwise has none (ours would act on a
    robot its author set up)."""
    if DEFAULT_BUTTONS.is_file():
        return DEFAULT_BUTTONS
    if Path("trees").is_dir() and not with_our_scenario:
        return None
    there = found(DEFAULT_BUTTONS)
    return there if there.is_file() else None


def resolve_profile(value: str | Path | None, trees: Sequence[Path]) -> Path | None:
    """A profile given by file or by name: ``child`` is ``profiles/child.yaml`` in the
    folder of the trees (or a folder above it, for a subtree in ``parts/``).

    Every command takes a profile this way; ConfigError when there is no such profile.
    """
    if value is None:
        return None
    path = Path(value)
    if path.suffix in (".yaml", ".yml") or path.exists():
        return path
    known: list[str] = []
    for tree in trees:
        folder = tree if tree.is_dir() else tree.parent
        for above in (folder, *folder.parents):
            candidate = above / "profiles" / f"{value}.yaml"
            if candidate.exists():
                return candidate
            known += [p.stem for p in sorted((above / "profiles").glob("*.yaml"))]
    names = list(dict.fromkeys(known))
    hint = did_you_mean(str(value), names) or (
        "give a profile file, or a name of " + ", ".join(names)
        if names
        else "give a profile file, or a name in trees/profiles/"
    )
    raise ConfigError(f"--profile {value}: no such profile ({hint})")


def dialogs_folder(given: Path | None) -> Path | None:
    """The dialogs folder: the one given with ``--dialogs`` (ConfigError when it is not
    a folder), else ``dialogs/`` when there is one."""
    if given is None:
        folder = found(DEFAULT_DIALOGS)
        return folder if folder.is_dir() else None
    if given.is_file():
        raise ConfigError(f"--dialogs {given}: a file; give the folder that holds it")
    if not given.is_dir():
        raise ConfigError(f"--dialogs {given}: no such folder")
    return given


def robot_catalogue(
    config: RobotConfig | None, registry: NodeRegistry | None = None
) -> KeyCatalogue:
    """The key catalogue of one robot: ``/devices/NAME/ok`` for each of its devices (and
    its camera) only
    (the default catalogue, without a robot, accepts any NAME), and the keys the
    registry's plugins add."""
    catalogue = registry.catalogue() if registry is not None else default_catalogue()
    if config is None:
        return catalogue
    pattern = catalogue.lookup("/devices/x/ok")
    specs = [spec for spec in catalogue if spec.name != _DEVICE_OK]
    if pattern is not None:
        specs += [
            KeySpec(
                f"/devices/{name}/ok", pattern.value_type, "", pattern.writer, pattern.description
            )
            for name in [*config.devices, *([CAMERA_NAME] if config.camera else [])]
        ]
    return KeyCatalogue(specs)


def load_config(path: Path, problems: Problems) -> RobotConfig | None:
    """The robot config, or None with its problems added."""
    try:
        return load_robot_config(path)
    except LoadError as error:
        problems.extend(error.problems)
        return None


def load_checked_behaviors(
    trees: list[Path],
    *,
    dialogs: Path | None,
    profile: Path | None,
    config: RobotConfig | None,
    problems: Problems,
) -> Behaviors | None:
    """Trees, dialogs and profile checked against the robot; None with problems added."""
    registry = default_registry()
    try:
        behaviors = load_behaviors(
            trees,
            dialogs_dir=dialogs,
            profile=profile,
            registry=registry,
            catalogue=robot_catalogue(config, registry),
        )
    except LoadError as error:
        problems.extend(error.problems)
        return None
    lengths = list_lengths(config)
    for definition in behaviors.trees:
        problems.extend(check_on_robot(definition, config, lengths))
    problems.extend(variable_problems(behaviors.trees, behaviors.loader.catalogue))
    return behaviors


@dataclass
class RunInputs:
    """Everything a run reads, checked."""

    behaviors: Behaviors
    config: RobotConfig
    scenario: Scenario
    buttons: ButtonBoard | None = None


def load_checked_buttons(
    path: Path, loader: TreeLoader, config: RobotConfig | None, problems: Problems
) -> ButtonBoard | None:
    """The therapist's buttons, their actions checked as trees are (against the robot's
    nodes, keys, pads and dialogs); None with problems added."""
    try:
        board = load_buttons(path, loader)
    except LoadError as error:
        problems.extend(error.problems)
        return None
    lengths = list_lengths(config)
    for button in board.buttons:
        if button.tree is not None:
            problems.extend(check_on_robot(button.tree, config, lengths))
    return board


def button_warnings(board: ButtonBoard, tree_names: list[str]) -> list[str]:
    """Buttons shown only while a tree runs that is not run: they never show."""
    warnings = []
    for button in board.buttons:
        running = button.when.running if button.when is not None else None
        if running is not None and running not in tree_names:
            hint = did_you_mean(running, tree_names) or "trees run: " + ", ".join(tree_names)
            warnings.append(
                f"warning: {button.mark}: button {button.label!r} shows only while "
                f"{running!r} runs, and no such tree runs ({hint})"
            )
    return warnings


def check_presses(
    events: Iterable[ScenarioEvent], board: ButtonBoard | None, buttons: Path | None
) -> list[Problem]:
    """A scenario presses only buttons the run has (by label)."""
    problems: list[Problem] = []
    labels = [button.label for button in board.buttons] if board is not None else []
    for event in events:
        if event.kind != "press":
            continue
        if buttons is None:
            problems.append(
                Problem(event.mark, "the scenario presses a button", "run with --buttons FILE")
            )
        elif board is not None and event.value not in labels:
            problems.append(
                Problem(
                    event.mark,
                    f"no button labelled {event.value!r} in {buttons}",
                    did_you_mean(str(event.value), labels) or "buttons: " + ", ".join(labels),
                )
            )
    return problems


def load_run_inputs(
    trees: list[Path],
    *,
    dialogs: Path | None,
    profile: str | None,
    hardware: Path,
    scenario: Path | None,
    buttons: Path | None = None,
) -> RunInputs:
    """What ``vest run`` checks at start-up; LoadError listing every problem of every file,
    ConfigError for a file or folder that is not there."""
    for path in trees:
        if not path.exists():
            raise ConfigError(
                f"{path}: no such file or folder (run from the project folder or pass --trees)"
            )
    folder = dialogs_folder(dialogs)
    profile_path = resolve_profile(profile, trees)
    problems = Problems()
    config = load_config(hardware, problems)
    behaviors = load_checked_behaviors(
        trees, dialogs=folder, profile=profile_path, config=config, problems=problems
    )
    board = None
    if buttons is not None and behaviors is not None:
        board = load_checked_buttons(buttons, behaviors.loader, config, problems)
        for tree in behaviors.trees:
            if tree.name == BUTTONS_TREE:
                problems.add(
                    tree.root.mark,
                    f"a tree may not be named {BUTTONS_TREE!r}: the therapist's buttons have it",
                    "rename the tree",
                )
    loaded: Scenario | None = None
    if config is not None:
        try:
            loaded = default_scenario(scenario, simulated=config.simulated)
        except LoadError as error:
            problems.extend(error.problems)
        if loaded is not None:
            problems.extend(check_scenario_events(loaded.events, config))
            problems.extend(check_presses(loaded.events, board, buttons))
    problems.raise_if_any()
    assert behaviors is not None and config is not None and loaded is not None
    return RunInputs(behaviors, config, loaded, board)


def default_scenario(path: Path | None, *, simulated: bool) -> Scenario:
    """The named scenario; by default the demo on the simulated vest, and on a real robot
    nothing scripted (the world is real) for as long as it runs."""
    if path is not None:
        return load_scenario(path)
    if simulated:
        return load_scenario(found(DEFAULT_SCENARIO))
    return Scenario(duration_s=float("inf"), events=(), path=Path("(no scenario)"))


def load_tree(
    tree: Path, profile_name: str | None, *, near: Path | None = None
) -> tuple[TreeDefinition, NodeRegistry]:
    """The tree file ``tree`` checked as ``vest run`` checks it (the dialogs beside it, or
    beside ``near``; the profile by name or path), and the registry of node types it was
    checked against."""
    from engine.loader.substitution import load_profile

    registry = default_registry()
    catalogue = registry.catalogue()
    folder = find_dialogs_folder(near or tree)
    dialogs = DialogLibrary.from_folder(folder, catalogue) if folder else None
    profile_path = resolve_profile(profile_name, [tree])  # by name or path, as vest run
    profile = load_profile(profile_path) if profile_path else None
    loader = TreeLoader(registry, catalogue, dialogs=dialogs, profile=profile)
    return loader.load(tree), registry

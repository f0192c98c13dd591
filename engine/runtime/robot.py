"""Loading a robot's behaviors and running them: trees, dialogs, profile, scheduler."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import IOT_INBOX, NOTHING, KeyCatalogue
from engine.clock import Clock
from engine.dialogs.library import DialogLibrary
from engine.files.problems import LoadError, Mark, Problem, Problems
from engine.files.yaml_source import YMap, load_yaml
from engine.loader.substitution import Profile, load_profile, read_params, undeclared_params
from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_file import TreeLoader
from engine.nodes.context import NodeErrorHandler, NodeErrorLog, TreeContext
from engine.nodes.registry import NodeRegistry, default_registry
from engine.runtime.scheduler import RunningTree, Scheduler
from engine.runtime.tree_watch import TreeNews
from engine.services.actions import SPOKEN_OVER, ActionLog, TreeActions, TurnTaking
from engine.services.interfaces import Services
from engine.services.jobs import Job
from engine.services.staged_readings import with_staged_readings
from engine.services.turns import SPEAKER, Turns
from engine.session.blackboard_news import BlackboardNews
from engine.session.events import SpokenOver, TurnTaken
from engine.session.stream import SessionStream
from engine.values.params import Key


def tree_files(paths: list[Path]) -> list[Path]:
    """Tree files named directly, and the ``*.yaml`` directly inside named folders.

    Subfolders (``parts/`` for subtrees, ``profiles/``) are not trees of their own.
    """
    files: list[Path] = []
    for path in paths:
        files.extend(sorted(path.glob("*.yaml")) if path.is_dir() else [path])
    return files


def declared_beside(profile: Path) -> set[str]:
    """Parameter names declared by the tree files a profile sits beside (its folder's
    parent, subfolders such as parts/ included), read from their ``params:`` only."""
    names: set[str] = set()
    if profile.parent.name != "profiles":
        return names  # a profile kept elsewhere serves the trees it is run with
    folder = profile.parent.parent
    for path in sorted(folder.rglob("*.yaml")):
        if path.parent == profile.parent:
            continue  # the profiles themselves
        try:
            document = load_yaml(path)
        except LoadError:
            continue  # a broken tree speaks for itself when it is loaded or validated
        if isinstance(document, YMap):
            names |= set(read_params(document.get("params"), Problems()))
    return names


@dataclass
class Behaviors:
    """Every validated tree, the dialogs they use, and the loader (for hot reload)."""

    trees: list[TreeDefinition]
    dialogs: DialogLibrary
    loader: TreeLoader


def load_behaviors(
    trees: list[Path],
    *,
    dialogs_dir: Path | None = None,
    profile: Path | None = None,
    registry: NodeRegistry | None = None,
    catalogue: KeyCatalogue | None = None,
) -> Behaviors:
    """Validate dialogs, the profile and every tree; LoadError listing all problems."""
    registry = registry or default_registry()
    catalogue = catalogue or registry.catalogue()
    problems = Problems()
    dialogs = DialogLibrary()
    checked_dialogs: DialogLibrary | None = dialogs
    if dialogs_dir is not None:
        try:
            dialogs = checked_dialogs = DialogLibrary.from_folder(dialogs_dir, catalogue)
        except LoadError as error:
            problems.extend(error.problems)
            checked_dialogs = None  # its own problems say why; no tree is blamed for it
    loaded_profile: Profile | None = None
    if profile is not None:
        try:
            loaded_profile = load_profile(profile)
        except LoadError as error:
            problems.extend(error.problems)
    loader = TreeLoader(registry, catalogue, dialogs=checked_dialogs, profile=loaded_profile)
    definitions: list[TreeDefinition] = []
    for path in tree_files(trees):
        try:
            definitions.append(loader.load(path))
        except LoadError as error:
            problems.extend(error.problems)
    if loaded_profile is not None and profile is not None and definitions and not problems:
        # a profile serves every tree beside it, not only those run now
        declared = set().union(*(d.declared_params for d in definitions))
        declared |= declared_beside(profile)
        where = (
            f"{profile.parent.parent}/" if profile.parent.name == "profiles" else "the trees run"
        )
        problems.extend(undeclared_params(loaded_profile, declared, where))
    names: dict[str, Path] = {}
    for definition in definitions:
        if definition.name in names:
            problems.add(
                definition.root.mark,
                f"two trees are named {definition.name!r} "
                f"(also {loader.shown(names[definition.name])})",
                "rename one",
            )
        names[definition.name] = definition.path
    problems.extend(unwritten_wake_keys(definitions))
    if not definitions and not problems:
        place = Mark(str(trees[0]) if trees else ".", 1, 1)
        problems.add(place, "no tree files (*.yaml) found", "name a tree file or a folder of them")
    problems.raise_if_any()
    return Behaviors(definitions, dialogs, loader)


def unwritten_wake_keys(definitions: list[TreeDefinition]) -> list[Problem]:
    """A tree that waits on a variable (``wake_on: [/vars/...]``) no tree writes would
    never wake: one problem each (the catalogue's keys each have their writer)."""
    written = {
        value
        for definition in definitions
        for node in definition.root.walk()
        for param in node.type.params
        if isinstance(param.type, Key) and param.type.access == "write"
        for value in [node.args.get(param.name)]
        if isinstance(value, str)
    }
    return [
        Problem(
            definition.root.mark,
            f"tree {definition.name!r} wakes on {key!r}, which no tree writes: it would rest "
            "for ever",
            "write it with save_as: or SetValue in another tree, or wake on a sensor key",
        )
        for definition in definitions
        for key in definition.wake_on
        if key.startswith("/vars/") and key not in written
    ]


THE_PERSON = "the person"
"""Who holds the speaker after speaking over the robot, in the turns' words."""
PERSONS_PRIORITY = 99
"""The person's turn outranks every tree (0..99: a tree of 99 waits); only the therapist's
buttons (100) speak over it."""


class Robot:
    """Built trees on one blackboard and clock, ticked by one scheduler; what happens is
    published on one session stream (``session``), which every reader subscribes to."""

    def __init__(
        self,
        behaviors: Behaviors,
        *,
        clock: Clock,
        services: Services,
        blackboard: Blackboard,
        session: SessionStream | None = None,
        on_node_error: NodeErrorHandler | None = None,
    ) -> None:
        self.behaviors = behaviors
        self.clock = clock
        self.services = services
        self.blackboard = blackboard
        self.session = session or SessionStream(clock)
        self.action_log = ActionLog(self.session)
        self.scheduler = Scheduler(clock, blackboard)
        self.turns = Turns(clock, stream=self.session, interrupt=self.interrupt)
        """Who has the speaker, the face LEDs and each joint."""
        self.tree_news = TreeNews(self.session)
        self.scheduler.after_tick.append(self.tree_news)
        news = BlackboardNews(self.session, blackboard.catalogue, clock, blackboard.carried_by)
        blackboard.watchers.append(news)
        self._staged = with_staged_readings(services, blackboard)  # readings reach every tree
        self._node_errors = on_node_error or NodeErrorLog()  # one count per node and error
        for definition in behaviors.trees:
            self.add_tree(definition)

    def add_tree(self, definition: TreeDefinition) -> RunningTree:
        """Build ``definition`` on this robot (its clock, blackboard, services and turns)
        and schedule it (within a step, trees tick by priority)."""
        context = TreeContext(
            tree=definition.name,
            clock=self.clock,
            blackboard=self.blackboard,
            actions=TreeActions(
                self._staged,
                self.clock,
                definition.name,
                self.action_log,
                taking=TurnTaking(
                    self.turns,
                    definition.priority,
                    definition.wait_for_turn_s,
                    definition.interruptible,
                ),
            ),
            dialogs=self.behaviors.dialogs,
            on_node_error=self._node_errors,
            session=self.session,
        )
        return self.scheduler.add(RunningTree(definition, context, definition.build(context)))

    @property
    def trees(self) -> list[RunningTree]:
        return self.scheduler.trees

    def begin_session(self, start_s: float) -> None:
        """The session starts at clock time ``start_s``: readers count from it, and every
        tree is published as it is now."""
        self.session.start_s = start_s
        for tree in self.trees:
            self.tree_news.started(tree)

    def spoken_over(self, from_s: float, saying: str, heard_last: bool, floor: Job) -> None:
        """A person's voice began at ``from_s`` (clock seconds) over the robot saying
        ``saying``, which has stopped: the tree that was saying it is halted as an
        interruption halts it (its other actions stop, its joints go to rest), without
        trying again: the person's words are what comes next (``heard_last``: the sentence's
        last part had begun, so a question ending it was put). Until ``floor`` is done the
        speaker is the person's (priority :data:`PERSONS_PRIORITY`): a tree waits for its
        turn or lets its sentence go, as it would for another tree."""
        speaking = [
            record
            for record in self.action_log.records
            if record.action == "say" and record.outcome is None
        ]
        # the sentence stopped is the first still under way that says it (another may be
        # queued behind it); what it carries of a person goes with it, and when no one
        # sentence is sure, what any of them carries (the consent gate then withholds it)
        exact = [record for record in speaking if record.args.get("text") == saying]
        said = exact[0] if exact else None
        tree = said.tree if said is not None else ""
        carries = said.carries if said is not None else NOTHING
        if said is None:
            carries = carries.union(*(record.carries for record in speaking))
        self.session.publish(
            SpokenOver(
                self.clock.now(),
                tree,
                said.action_id if said is not None else 0,
                saying,
                from_s,
                carries,
            )
        )
        if tree:
            self.scheduler.tree(tree).halt(SPOKEN_OVER, heard_last=heard_last)
        self.turns.hold((SPEAKER,), THE_PERSON, PERSONS_PRIORITY, floor)

    def person_speaks(self, from_s: float, floor: Job) -> None:
        """A person began to speak at ``from_s`` (clock seconds) while the robot was
        silent: until ``floor`` is done (what they said is heard) the speaker is theirs
        (priority :data:`PERSONS_PRIORITY`), so no tree starts a sentence over them; a
        tree waits for its turn or lets its sentence go, as it would for another tree. A
        sentence that began meanwhile is left to finish (a voice over it stops it)."""
        if self.turns.holder(SPEAKER, THE_PERSON) is None:
            self.turns.hold((SPEAKER,), THE_PERSON, PERSONS_PRIORITY, floor)

    def refuse_commands(self, trees: Iterable[RunningTree], why: str) -> None:
        """Each operator's command that came to ``trees`` and that none of their nodes
        took is reported failed at once (``not carried out: why``): an operator is never
        left waiting for a command that will not be carried out."""
        for tree in trees:
            for command in tree.events.take_unread(IOT_INBOX):
                if isinstance(command, Mapping) and "id" in command:
                    tree.context.actions.report_result(
                        str(command["id"]), "failed", {"error": f"not carried out: {why}"}
                    )

    def interrupt(self, name: str, by: str, resource: str) -> None:
        """Halt tree ``name`` cleanly because ``by`` takes ``resource``: its actions stop
        (cut short), its joints go back to rest and its LEDs off. It starts afresh at its
        next tick: with the events of the round cut short when it tries again (once)."""
        if name == THE_PERSON:
            return  # the person's turn is over: nothing of theirs to halt
        tree = self.scheduler.tree(name)
        # once: a round cut short again while trying again lets go (no stutter), and
        # without wait_for_turn_s there would be no waiting for the turn at all
        again = tree.tries_again and tree.definition.wait_for_turn_s > 0 and not tree.retrying
        tree.halt(f"{by} interrupted it", tried_again=again)
        if again:
            tree.try_again()
            self.session.publish(TurnTaken(self.clock.now(), name, "tries_again", resource, by))

"""TreeHarness: load one YAML tree and drive it on the robot's scheduler, on a virtual clock."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from py_trees.common import Status

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import KeyCatalogue, default_catalogue
from engine.blackboard.events import EventLog
from engine.clock import VirtualClock
from engine.dialogs.library import DialogLibrary, find_dialogs_folder
from engine.loader.substitution import load_profile
from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_file import TreeLoader
from engine.nodes.context import TreeContext
from engine.nodes.registry import NodeRegistry, default_registry
from engine.runtime.scheduler import RunningTree, Scheduler
from engine.scenario.world import BlackboardSenses, World
from engine.services.actions import ActionLog, ActionRecord, TreeActions
from engine.services.interfaces import Services
from engine.services.simulated import simulated_services
from engine.services.staged_readings import with_staged_readings


class TreeHarness:
    """One tree, a fresh blackboard, a virtual clock, recording services and a world.

    ``world`` answers on-request sensor reads (``world.temperature_c = 22.2``);
    ``services`` are the simulated services (``services.speech.fail_next = "why"``).

    Each harness is a robot of its own, with its own blackboard: two harnesses (say, two
    profiles) run side by side and never see each other's keys.
    """

    def __init__(
        self,
        definition: TreeDefinition,
        *,
        dialogs: DialogLibrary | None = None,
        catalogue: KeyCatalogue | None = None,
        clock: VirtualClock | None = None,
        services: Services | None = None,
        keep_node_errors: bool = False,
    ) -> None:
        self.keep_node_errors = keep_node_errors
        self.definition = definition
        self.clock = clock or VirtualClock()
        self.blackboard = Blackboard(catalogue or default_catalogue(), self.clock)
        self.blackboard.reset()
        self.world = World()
        self.senses = BlackboardSenses(self.blackboard, self.world)
        self.services = services or simulated_services(self.clock, readers=self.senses.readers())
        self.log = ActionLog()
        self.node_errors: list[tuple[str, BaseException]] = []
        self.node_warnings: list[tuple[str, str]] = []
        self.context = TreeContext(
            tree=definition.name,
            clock=self.clock,
            blackboard=self.blackboard,
            actions=TreeActions(
                with_staged_readings(self.services, self.blackboard),
                self.clock,
                definition.name,
                self.log,
            ),
            dialogs=dialogs,
            on_node_error=self._node_error,
            on_node_warning=lambda tree, path, message: self.node_warnings.append((path, message)),
        )
        self.scheduler = Scheduler(self.clock, self.blackboard)
        self.running = self.scheduler.add(
            RunningTree(definition, self.context, definition.build(self.context))
        )
        self.tree = self.running.tree
        self.ticks = 0

    def _node_error(self, tree: str, path: str, error: BaseException) -> None:
        """A node raised: the test fails with that exception after the step (:meth:`tick`),
        unless it asked to keep node errors as data (``keep_node_errors=True``:
        ``node_errors``, the node FAILURE)."""
        self.node_errors.append((path, error))

    @classmethod
    def from_file(
        cls,
        path: str | Path,
        profile: str | Path | None = None,
        *,
        dialogs_dir: str | Path | None = None,
        registry: NodeRegistry | None = None,
        keep_node_errors: bool = False,
    ) -> TreeHarness:
        """Load and validate a tree file (LoadError with file:line:column on problems).

        ``dialogs_dir`` defaults to the nearest ``dialogs/`` folder at or above the tree.
        """
        path = Path(path)
        registry = registry or default_registry()
        catalogue = registry.catalogue()
        folder = Path(dialogs_dir) if dialogs_dir is not None else find_dialogs_folder(path)
        dialogs = DialogLibrary.from_folder(folder, catalogue) if folder else DialogLibrary()
        loaded_profile = load_profile(Path(profile)) if profile is not None else None
        loader = TreeLoader(registry, catalogue, dialogs=dialogs, profile=loaded_profile)
        return cls(
            loader.load(path),
            dialogs=dialogs,
            catalogue=catalogue,
            keep_node_errors=keep_node_errors,
        )

    # -- the world ------------------------------------------------------------------------
    def set(self, key: str, value: Any) -> None:
        """Write ``key`` (an event key gets one new event), seen from the next tick on."""
        if self._is_event(key):
            self.blackboard.stage_event(key, value)
        else:
            self.blackboard.stage(key, value)

    def get(self, key: str, default: Any = None) -> Any:
        """The value of ``key`` (for an event key, the latest event's value)."""
        value = self.blackboard.get(key, default)
        if isinstance(value, EventLog):
            return value.latest.value if value.latest else default
        return value

    def _is_event(self, key: str) -> bool:
        spec = self.blackboard.catalogue.lookup(key)
        return spec is not None and spec.kind == "event"

    # -- time -----------------------------------------------------------------------------
    @property
    def period_s(self) -> float:
        return 1.0 / self.definition.rate_hz

    @property
    def now(self) -> float:
        """Seconds since the harness started."""
        return self.clock.now()

    def tick(self, n: int = 1) -> Status:
        """Let ``n`` of the tree's periods pass under the robot's own scheduler (each a
        step at the tree's deadline: it commits what was staged and ticks the tree, unless
        the tree rests until a key it wakes on changes); the last status. A node that
        raised fails the test (unless ``keep_node_errors``)."""
        for _ in range(n):
            errors = len(self.node_errors)
            self.clock.sleep_until(self.running.next_deadline_s)
            if self.running in self.scheduler.step():
                self.ticks += 1
            if len(self.node_errors) > errors and not self.keep_node_errors:
                raise self.node_errors[-1][1]
            self.clock.sleep_until(self.running.next_deadline_s)  # a period has passed
        return self.status

    def advance(self, seconds: float) -> Status:
        """Let ``seconds`` pass, ticking at the tree's rate."""
        return self.tick(max(1, round(seconds * self.definition.rate_hz)))

    # -- what happened --------------------------------------------------------------------
    @property
    def status(self) -> Status:
        return self.tree.root.status

    @property
    def actions(self) -> list[ActionRecord]:
        """Every service call so far, failed ones included: time, tree, action (say, led,
        servo, ...), args, and ``error`` (None unless the service failed the call)."""
        return list(self.log.records)

    @property
    def failed_actions(self) -> list[ActionRecord]:
        """The service calls the service failed (``record.error`` says why)."""
        return [record for record in self.log.records if record.error is not None]

    def did(self, action: str) -> list[dict[str, Any]]:
        """The arguments of every call of ``action`` (``"led"``, ``"servo"``, ...) that did not
        fail (one still under way counts)."""
        return [record.args for record in self.log.done if record.action == action]

    @property
    def said(self) -> list[str]:
        """Every phrase the robot said (or is saying), in order; not those it failed to say."""
        return [args["text"] for args in self.did("say")]

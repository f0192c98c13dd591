"""Base classes for leaf nodes: conditions and actions.

A developer writes a leaf in a few lines::

    class IsWarm(Condition):
        \"\"\"True when the room is warmer than a threshold.

        SUCCESS when the last temperature reading is above ``above_c``; FAILURE otherwise
        or when no reading exists yet.
        \"\"\"

        above_c = Param("above_c", Number(unit="degC"), 25.0, "threshold in degC")
        reads = ("/sensors/temperature/c",)

        def check(self) -> bool:
            return (self.read("/sensors/temperature/c") or -273.0) > self.above_c

and registers it: ``registry.add(IsWarm)``. Parameters are declared with types, defaults
and docs; the loader validates YAML against them and ``vest nodes`` lists them. Each
declared parameter is also a typed attribute: ``self.above_c`` is a ``float`` to mypy.

An exception inside any leaf, or an ``update()`` that returns something other than a
Status, makes that node FAILURE, is reported with the node's path, and the tree keeps
ticking.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Mapping
from types import SimpleNamespace
from typing import Any, ClassVar

import py_trees
from py_trees.common import Status

from engine.blackboard.catalogue import Carries
from engine.nodes.context import TreeContext
from engine.nodes.spec import NodeType
from engine.services.jobs import Job
from engine.values.param_problems import CheckContext, ParamIssue
from engine.values.params import Param


def node_path(node: py_trees.behaviour.Behaviour) -> str:
    """``root/…/node`` names from the tree's root to ``node``."""
    names = []
    current: py_trees.behaviour.Behaviour | None = node
    while current is not None:
        names.append(current.name)
        current = current.parent
    return "/".join(reversed(names))


class Leaf(py_trees.behaviour.Behaviour):
    """Base of vest leaf nodes. Subclasses set the class attributes and lifecycle methods.

    Class attributes: each parameter as ``name = Param("name", Type(), default, doc)``
    (then ``self.name`` is its converted, typed value; a ``params`` tuple of
    :class:`Param` also works, read as ``self.args.name``), ``kind`` ("condition" or
    "action"), ``reads`` / ``writes`` (fixed blackboard keys; keys given as ``Key``
    parameters are added automatically), ``type_name`` (defaults to the class name).
    ``self.args`` holds every converted parameter, ``self.ctx`` the tree's context.
    """

    kind: ClassVar[str] = "action"
    type_name: ClassVar[str | None] = None
    params: ClassVar[tuple[Param[Any], ...]] = ()
    reads: ClassVar[tuple[str, ...]] = ()
    writes: ClassVar[tuple[str, ...]] = ()
    uses: ClassVar[tuple[str, ...]] = ()
    """What the node uses of the robot (:data:`~engine.nodes.spec.RESOURCES`: the speaker,
    the face LEDs, the joint its ``joint`` parameter names, any joint): trees of one
    priority that use the same are named at load time, and the robot checks read it."""
    _guarding: bool = False
    """True while a guarded lifecycle method runs (a subclass calling super() is not
    guarded twice)."""
    _failed_to_start: Exception | None = None
    """What initialise() raised, answered as FAILURE by the update() after it."""

    def __init__(self, name: str, args: SimpleNamespace, ctx: TreeContext) -> None:
        super().__init__(name)
        self.args = args
        self.ctx = ctx
        read_keys, write_keys = leaf_type(type(self)).keys(vars(args))
        self.read_keys = tuple(dict.fromkeys(read_keys))
        self.write_keys = frozenset(write_keys)

    @classmethod
    def check_params(cls, args: Mapping[str, Any], ctx: CheckContext) -> list[ParamIssue]:
        """Checks across parameters at load time: (parameter, message, hint) per problem."""
        return []

    # -- helpers for subclasses ---------------------------------------------------------
    def read(self, key: str, default: Any = None) -> Any:
        """The committed value of ``key`` on this robot's blackboard, or ``default`` when
        it has none yet."""
        return self.ctx.blackboard.get(key, default)

    def write(self, key: str, value: Any, *, carries: Carries | None = None) -> None:
        """Write one of this tree's variables (``/vars/...``) now: only a key the node
        declared it writes (in ``writes`` or a write ``Key`` parameter). ``carries``: what
        of a person ``value`` was made from; by default what the node reads
        (:meth:`carries`), which is never less than the truth."""
        if key not in self.write_keys:
            raise PermissionError(
                f"{type(self).__name__} writes {key!r} but does not declare it "
                f"(it declares {sorted(self.write_keys) or 'no writes'})"
            )
        made_of = self.carries() if carries is None else carries
        self.ctx.blackboard.set(key, value, carries=made_of)

    def carries(self) -> Carries:
        """What of a person this node's outputs (its writes, its actions' arguments, its
        feedback) may hold: what the keys it reads hold now (a sensor's readings, what
        was heard, a variable made from either). A node that knows better passes
        ``carries`` to :meth:`write` or to its action."""
        return self.ctx.blackboard.carried_by(self.read_keys)

    def now(self) -> float:
        """The engine clock, in seconds."""
        return self.ctx.clock.now()

    def job_status(self, job: Job, *, failed: str = "could not act") -> Status:
        """RUNNING while ``job`` runs; FAILURE when it failed (the feedback says why and
        starts with ``failed``); SUCCESS when it is done."""
        if not job.done():
            return Status.RUNNING
        error = job.error()
        if error is not None:
            self.feedback_message = f"{failed}: {error}"
            return Status.FAILURE
        return Status.SUCCESS

    def terminate(self, new_status: Status) -> None:
        """Pre-empted (INVALID): cancel the service job this node started, if still going."""
        job = getattr(self, "job", None)
        if new_status != Status.INVALID or job is None:
            return
        if getattr(job, "waiting", False) or not job.done():  # asking a waiting job starts it
            job.cancel()

    # -- the safety net -----------------------------------------------------------------
    def __init_subclass__(cls, **kwargs: Any) -> None:
        """Guard the lifecycle methods a leaf class defines (py_trees says not to override
        ``tick()``): an exception in ``initialise``, ``update`` or ``terminate``, or an
        ``update`` that returns no Status, makes the node FAILURE, reported with its path;
        the tree keeps ticking."""
        super().__init_subclass__(**kwargs)
        for method in ("initialise", "update", "terminate"):
            if method in cls.__dict__:
                setattr(cls, method, _GUARDS[method](cls.__dict__[method]))

    def _report(self, error: Exception) -> None:
        self.feedback_message = f"{type(error).__name__}: {error}"
        self.ctx.on_node_error(self.ctx.tree, node_path(self), error)


def _guard_initialise(method: Callable[[Leaf], None]) -> Callable[[Leaf], None]:
    @functools.wraps(method)
    def initialise(self: Leaf) -> None:
        if self._guarding:  # a subclass's initialise calls super's
            return method(self)
        self._guarding = True
        self.ctx.actions.acting = self  # its actions are made of what it reads
        try:
            method(self)
        except Exception as error:
            self._failed_to_start = error  # update() then answers FAILURE
        finally:
            self._guarding = False
            self.ctx.actions.acting = None

    return initialise


def _guard_update(method: Callable[[Leaf], Any]) -> Callable[[Leaf], Status]:
    @functools.wraps(method)
    def update(self: Leaf) -> Status:
        if self._guarding:
            return method(self)  # type: ignore[no-any-return]
        if self._failed_to_start is not None:
            failed, self._failed_to_start = self._failed_to_start, None
            self._report(failed)
            return Status.FAILURE
        self._guarding = True
        self.ctx.actions.acting = self
        try:
            status = method(self)
            if not isinstance(status, Status):  # py_trees would make it INVALID, silently
                raise TypeError(f"{type(self).__name__}.update() returned {status!r}, not a Status")
            return status
        except Exception as error:
            self._report(error)
            return Status.FAILURE
        finally:
            self._guarding = False
            self.ctx.actions.acting = None

    return update


def _guard_terminate(method: Callable[[Leaf, Status], None]) -> Callable[[Leaf, Status], None]:
    @functools.wraps(method)
    def terminate(self: Leaf, new_status: Status) -> None:
        if self._guarding:
            return method(self, new_status)
        self._guarding = True
        self.ctx.actions.acting = self
        try:
            method(self, new_status)
        except Exception as error:  # a failing terminate() must not stop the tick either
            self._report(error)
        finally:
            self._guarding = False
            self.ctx.actions.acting = None

    return terminate


_GUARDS: dict[str, Callable[[Any], Any]] = {
    "initialise": _guard_initialise,
    "update": _guard_update,
    "terminate": _guard_terminate,
}
Leaf.terminate = _guard_terminate(Leaf.terminate)  # type: ignore[method-assign,assignment]


class Condition(Leaf):
    """A yes/no question about the blackboard: implement :meth:`check`.

    SUCCESS when the answer is yes, FAILURE when no. Never RUNNING.
    """

    kind: ClassVar[str] = "condition"

    def check(self) -> bool:
        raise NotImplementedError(f"{type(self).__name__} must implement check()")

    def update(self) -> Status:
        return Status.SUCCESS if self.check() else Status.FAILURE


class ServiceAction(Leaf):
    """An action done by a service: implement :meth:`start` returning a Job.

    RUNNING while the job runs; SUCCESS when it finished; FAILURE when the service could
    not do it (``feedback_message`` says why). Pre-empted, it cancels the job.
    """

    kind: ClassVar[str] = "action"

    def __init__(self, name: str, args: SimpleNamespace, ctx: TreeContext) -> None:
        super().__init__(name, args, ctx)
        self.job: Job | None = None

    def start(self) -> Job:
        raise NotImplementedError(f"{type(self).__name__} must implement start()")

    def finished(self, job: Job) -> Status:
        """Called once the job succeeded; may use its result. Returns SUCCESS by default."""
        return Status.SUCCESS

    def initialise(self) -> None:
        self.job = None
        self.job = self.start()

    def update(self) -> Status:
        if self.job is None:
            return Status.FAILURE
        status = self.job_status(self.job)
        return self.finished(self.job) if status == Status.SUCCESS else status


def leaf_type(cls: type[Leaf], *, source: str = "vest", **bound: Any) -> NodeType:
    """The :class:`NodeType` of a leaf class (its name is ``cls.type_name`` or the class name).

    ``bound`` are keyword arguments every node of the type is built with, after
    ``(name, args, ctx)``: its own services, as BehaviorTree.CPP's registerNodeType
    forwards constructor arguments (``registry.add(Greeter, speaker=my_speaker)``).
    """
    if not (isinstance(cls, type) and issubclass(cls, Leaf)):
        what = cls.__name__ if isinstance(cls, type) else repr(cls)
        plain = isinstance(cls, type) and issubclass(cls, py_trees.behaviour.Behaviour)
        raise TypeError(
            f"{what} is "
            + ("a plain py_trees behaviour" if plain else "not a node class")
            + ": subclass engine.nodes.Condition, ServiceAction or Leaf (they declare the "
            "parameters and blackboard keys the loader checks), or register a NodeType"
        )
    if bound:
        try:
            inspect.signature(cls).bind(None, None, None, **bound)
        except TypeError as error:
            raise TypeError(
                f"{cls.__name__} cannot take {', '.join(sorted(bound))}: {error}; declare "
                "them as keyword parameters of its __init__(self, name, args, ctx, *, ...)"
            ) from None
    if cls.kind not in ("condition", "action"):
        raise TypeError(f"{cls.__name__}.kind must be 'condition' or 'action', not {cls.kind!r}")
    outside = [key for key in cls.writes if not key.startswith("/vars/")]
    if outside:
        raise TypeError(
            f"{cls.__name__}.writes names {outside}: trees write only /vars/ keys; a sensor's "
            "readings are staged by its poller or service"
        )
    params = declared_params(cls)
    names = [p.name for p in params]
    if len(set(names)) != len(names) or "name" in names:
        raise TypeError(f"{cls.__name__}.params: names must be unique and not 'name'")

    def build(
        name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext
    ) -> py_trees.behaviour.Behaviour:
        return cls(name, args, ctx, **bound)

    return NodeType(
        name=cls.type_name or cls.__name__,
        kind="condition" if cls.kind == "condition" else "action",
        doc=inspect.cleandoc(cls.__doc__ or ""),
        params=params,
        build=build,
        check=cls.check_params if _overrides(cls, "check_params") else None,
        fixed_reads=tuple(cls.reads),
        fixed_writes=tuple(cls.writes),
        source=source,
        uses=tuple(cls.uses) if isinstance(cls.uses, list) else cls.uses,
    )


_NODE_ATTRIBUTES = frozenset(
    {
        "name",
        "status",
        "parent",
        "children",
        "logger",
        "feedback_message",
        "blackboards",
        "qualified_name",
        "id",
        "iterator",
        "blackbox_level",
        "args",
        "ctx",
        "blackboard",
        "job",
        "write_keys",
    }
)
"""Attributes every node instance sets itself: a parameter of one of these names would be
hidden by it."""


def declared_params(cls: type[Leaf]) -> tuple[Param[Any], ...]:
    """A leaf class's parameters: its ``params`` tuple, then every :class:`Param` declared
    as a class attribute (base classes first, in the order they are written)."""
    attributes: dict[str, Param[Any]] = {}
    for klass in reversed(cls.__mro__):
        for attribute, value in vars(klass).items():
            if isinstance(value, Param):
                if attribute in _NODE_ATTRIBUTES or hasattr(Leaf, attribute):
                    raise TypeError(
                        f"{cls.__name__}.{attribute}: a parameter cannot be named like an "
                        "attribute every node has; choose another name"
                    )
                attributes[attribute] = value
    listed = tuple(cls.params)
    listed_names = {param.name for param in listed}
    return listed + tuple(p for name, p in attributes.items() if name not in listed_names)


def _overrides(cls: type, method: str) -> bool:
    return getattr(cls, method) is not getattr(Leaf, method)

"""What crosses the wire, one schema per direction (no token or digest ever does)."""

from __future__ import annotations

import json
import math
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    StrictBool,
    StrictInt,
    StringConstraints,
)

from cloud.store.ledger import Command, CommandState

MAX_DEPTH = 16


def checked_json(value: Any, depth: int = 0) -> Any:
    """``value`` if every number in it is finite, every text (keys included) is valid
    Unicode, and it nests at most MAX_DEPTH deep. JSON has no NaN or infinity; a lone
    surrogate (``"\\ud800"``) parses but can be neither stored in PostgreSQL nor sent back."""
    if depth > MAX_DEPTH:
        raise ValueError(f"nests deeper than {MAX_DEPTH} levels")
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"numbers must be finite, got {value}")
    if isinstance(value, str):
        valid_text(value)
    elif isinstance(value, dict):
        for key, item in value.items():
            valid_text(key)
            checked_json(item, depth + 1)
    elif isinstance(value, list):
        for item in value:
            checked_json(item, depth + 1)
    return value


def valid_text(text: str) -> str:
    """``text`` if a database can store it: valid Unicode (a lone surrogate is not) and no
    NUL character (PostgreSQL's text and JSON cannot hold one)."""
    if not text.isascii():  # ASCII holds no surrogate: only other text is encoded to see
        try:
            text.encode("utf-8")
        except UnicodeEncodeError:
            raise ValueError("text must be valid Unicode (a lone surrogate is not)") from None
    if "\x00" in text:
        raise ValueError("text must not hold a NUL character (\\u0000)")
    return text


Json = Annotated[Any, AfterValidator(checked_json)]
JsonObject = Annotated[dict[str, Any], AfterValidator(checked_json)]
TelemetryKey = Annotated[str, StringConstraints(min_length=1, max_length=200)]
"""Checked as text a database can store by ``checked_json`` on the whole mapping."""
Key = Annotated[str, StringConstraints(min_length=1, max_length=128), AfterValidator(valid_text)]


class CommandCreate(BaseModel):
    model_config = ConfigDict(extra="forbid")

    type: str = Field(min_length=1, max_length=64, pattern=r"^[a-z][a-z0-9_]*$")
    args: JsonObject = Field(default_factory=dict)
    idempotency_key: Key | None = None
    timeout_s: float | None = Field(default=None, gt=0, le=86400, strict=True)
    """Seconds, a number (``true`` or ``"5"`` is refused, not taken as 1 or 5)."""


class CommandPublic(BaseModel):
    id: str
    robot: str
    type: str
    args: dict[str, Any]
    state: CommandState
    version: int
    result: Any = None
    result_hidden: bool = False
    """The robot's result is not shown to this account's role (a result may carry sensor
    values, which a viewer never sees)."""
    created_s: float
    updated_s: float
    deliveries: int

    @classmethod
    def of(cls, command: Command, robot: str, *, with_result: bool = True) -> CommandPublic:
        """``command`` as the API shows it; without its result for a role that may not
        see sensor values (``with_result`` False)."""
        hidden = not with_result and command.result is not None
        return cls(
            id=command.id,
            robot=robot,
            type=command.type,
            args=command.args,
            state=command.state,
            version=command.version,
            result=None if hidden else command.result,
            result_hidden=hidden,
            created_s=command.created_s,
            updated_s=command.updated_s,
            deliveries=command.deliveries,
        )


class ClaimedCommand(CommandPublic):
    """A command as the robot takes it: ``lease_s`` is how long it has to report it, or to
    say it is still at it (``POST .../progress``), before it is delivered again."""

    lease_s: float


class ResultReport(BaseModel):
    model_config = ConfigDict(extra="forbid")

    status: Literal["SUCCEEDED", "FAILED"]
    result: Json = None


MAX_VALUE_BYTES = 1024
"""The largest telemetry value, as JSON (a sensor's reading, a list of pads: far less)."""


_NUMBERS = (int, float)  # bool is an int
_LARGEST_INT = 2**63  # a reading as a database stores it; 20 characters of JSON at most


def _small_number(value: Any) -> bool:
    """A finite float (24 characters of JSON at most) or an int within 64 bits."""
    if isinstance(value, float):
        return math.isfinite(value)
    return isinstance(value, int) and -_LARGEST_INT <= value < _LARGEST_INT


def small_values(values: dict[str, Any]) -> dict[str, Any]:
    """``values`` if each is JSON a database can store (:func:`checked_json`) and at most
    :data:`MAX_VALUE_BYTES` of it; in one pass, numbers and short lists of them at once
    (a robot pushes every second)."""
    for key, value in values.items():
        valid_text(key)
        if isinstance(value, _NUMBERS):
            if not _small_number(value):
                raise ValueError(
                    f"the value of {key!r} must be a finite number within 64 bits, "
                    f"got {str(value)[:24]}"
                )
            continue
        checked_json(value, 1)
        if value is None or (isinstance(value, str) and len(value) <= MAX_VALUE_BYTES // 6):
            continue  # even escaped, it fits
        if (
            isinstance(value, list)
            and len(value) <= 32
            and all(_small_number(item) for item in value)
        ):
            continue  # a sensor's list of readings: at most 32 x 25 bytes, below the bound
        size = len(json.dumps(value, separators=(",", ":")))
        if size > MAX_VALUE_BYTES:
            raise ValueError(
                f"the value of {key!r} is {size} bytes of JSON; at most {MAX_VALUE_BYTES}"
            )
    return values


class TelemetryReport(BaseModel):
    """Up to 500 keys a push, each value at most 1 KiB of JSON; a robot's telemetry holds
    at most 500 keys in all (a push that would add more is a 422)."""

    model_config = ConfigDict(extra="forbid")

    values: Annotated[dict[TelemetryKey, Any], AfterValidator(small_values)] = Field(max_length=500)


Words = Annotated[str, Field(max_length=2000)]


class ViewTree(BaseModel):
    model_config = ConfigDict(extra="forbid")

    tree: Words
    priority: StrictInt
    status: Words
    doing: list[Words] = Field(max_length=100)


class ViewLine(BaseModel):
    """One line of "what happened": when (seconds into the session), who, what, its tone."""

    model_config = ConfigDict(extra="forbid")

    at: float = Field(allow_inf_nan=False)
    who: Words
    what: Words
    tone: Words


class ViewButton(BaseModel):
    model_config = ConfigDict(extra="forbid")

    id: StrictInt
    label: Words
    key: Words | None = None
    control: Words | None = None


class ViewBoard(BaseModel):
    model_config = ConfigDict(extra="forbid")

    buttons: list[ViewButton] = Field(max_length=200)
    shown: list[StrictInt] = Field(max_length=200)
    paused: StrictBool
    doing: Words | None = None


class SessionView(BaseModel):
    """The robot's live session as the cloud's page shows it (engine/view/cloud_session.py):
    every tree and what it does, the latest lines of what happened, its buttons."""

    model_config = ConfigDict(extra="forbid")

    trees: list[ViewTree] = Field(max_length=200)
    happened: list[ViewLine] = Field(max_length=100)
    board: ViewBoard | None = None
    ended: StrictBool = False


class SessionViewReport(BaseModel):
    """A robot's push of its session; the page renders what this checks, and nothing
    else (a view of another shape is a 422, never a page that breaks)."""

    model_config = ConfigDict(extra="forbid")

    view: SessionView


class PressCreate(BaseModel):
    """A press of the robot's button ``button`` (its number on the board, as the board
    in the session view numbers it, from 0)."""

    model_config = ConfigDict(extra="forbid")

    button: StrictInt = Field(ge=0, le=999)


class RobotPublic(BaseModel):
    name: str
    online: bool
    last_seen_s: float | None


class AccountPublic(BaseModel):
    """A person's account as they see it: ``expires_at_s`` in seconds since the epoch
    (None: the token never expires)."""

    name: str
    role: str
    can_command: bool
    can_press: bool
    sees_telemetry: bool
    expires_at_s: float | None


class Problem(BaseModel):
    """One thing wrong with a request: the field (``body`` for the whole) and why."""

    field: str
    message: str


class Problems(BaseModel):
    """A 422: every problem of the request."""

    detail: list[Problem]


class Refusal(BaseModel):
    """A 401, 403, 404, 409, 413 or 503: why, in words."""

    detail: str


ERRORS: dict[int | str, dict[str, Any]] = {
    401: {"model": Refusal, "description": "no token, or one unknown, revoked or expired"},
    403: {"model": Refusal, "description": "the account's role may not do this (it is named)"},
    404: {"model": Refusal, "description": "nothing of that name this caller may see"},
    409: {"model": Refusal, "description": "it contradicts how the command already ended"},
    413: {"model": Refusal, "description": "the body is larger than the service takes"},
    422: {"model": Problems, "description": "a field is wrong: each one named, with why"},
    503: {"model": Refusal, "description": "the database cannot store it now: ask again later"},
}
"""The answers every route may give besides its own, as the service sends them."""

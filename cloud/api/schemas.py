"""What crosses the wire, one schema per direction (no token or digest ever does)."""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, StringConstraints

from cloud.store.ledger import Command

MAX_DEPTH = 16


def finite_json(value: Any, depth: int = 0) -> Any:
    """``value`` if every number in it is finite and it nests at most MAX_DEPTH deep (JSON
    has no NaN or infinity, and PostgreSQL refuses them)."""
    if depth > MAX_DEPTH:
        raise ValueError(f"nests deeper than {MAX_DEPTH} levels")
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"numbers must be finite, got {value}")
    if isinstance(value, dict):
        for item in value.values():
            finite_json(item, depth + 1)
    elif isinstance(value, list):
        for item in value:
            finite_json(item, depth + 1)
    return value


Json = Annotated[Any, AfterValidator(finite_json)]
JsonObject = Annotated[dict[str, Any], AfterValidator(finite_json)]
TelemetryKey = Annotated[str, StringConstraints(min_length=1, max_length=200)]


class CommandCreate(BaseModel):
    model_config = ConfigDict(extra="forbid")

    type: str = Field(min_length=1, max_length=64, pattern=r"^[a-z][a-z0-9_]*$")
    args: JsonObject = Field(default_factory=dict)
    idempotency_key: str | None = Field(default=None, min_length=1, max_length=128)
    timeout_s: float | None = Field(default=None, gt=0, le=86400)


class CommandPublic(BaseModel):
    id: str
    robot: str
    type: str
    args: dict[str, Any]
    state: str
    version: int
    result: Any = None
    created_s: float
    updated_s: float
    deliveries: int

    @classmethod
    def of(cls, command: Command, robot: str) -> CommandPublic:
        return cls(
            id=command.id,
            robot=robot,
            type=command.type,
            args=command.args,
            state=command.state,
            version=command.version,
            result=command.result,
            created_s=command.created_s,
            updated_s=command.updated_s,
            deliveries=command.deliveries,
        )


class ResultReport(BaseModel):
    model_config = ConfigDict(extra="forbid")

    status: Literal["SUCCEEDED", "FAILED"]
    result: Json = None


class TelemetryReport(BaseModel):
    model_config = ConfigDict(extra="forbid")

    values: Annotated[dict[TelemetryKey, Any], AfterValidator(finite_json)] = Field(max_length=500)


class RobotPublic(BaseModel):
    name: str
    online: bool
    last_seen_s: float | None

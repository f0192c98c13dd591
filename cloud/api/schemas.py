"""What crosses the wire, one schema per direction (no token or digest ever does)."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from cloud.store.ledger import Command


class CommandCreate(BaseModel):
    model_config = ConfigDict(extra="forbid")

    type: str = Field(min_length=1, max_length=64, pattern=r"^[a-z][a-z0-9_]*$")
    args: dict[str, Any] = Field(default_factory=dict)
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
    result: Any = None


class TelemetryReport(BaseModel):
    model_config = ConfigDict(extra="forbid")

    values: dict[str, Any] = Field(max_length=500)


class RobotPublic(BaseModel):
    name: str
    online: bool
    last_seen_s: float | None

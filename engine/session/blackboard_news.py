"""What the blackboard's commits say, as session events.

A blackboard watcher: each committed write that says something new becomes a
:class:`~engine.session.events.KeyChanged` (every event, and a state key's write only when
its value changed: a sensor polled 20 times a second mostly repeats), and the writes that
are happenings of their own become their own events: what the robot heard, a hand it saw,
someone it could not listen to, a device going offline or coming back.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from engine.blackboard.catalogue import (
    DEVICES_PREFIX,
    HAND_SHOWN,
    NOTHING,
    SPEECH_HEARD,
    SPEECH_NOT_LISTENED,
    VARIABLES_PREFIX,
    Carries,
    KeyCatalogue,
)
from engine.clock import Clock
from engine.session.events import DeviceChanged, HandShown, Heard, KeyChanged, NotListened
from engine.session.json_values import json_text
from engine.session.stream import SessionStream


class ChangedKeys:
    """Which blackboard writes say something new: every event, and a state key's write
    only when its value changed."""

    def __init__(self, catalogue: KeyCatalogue) -> None:
        self.catalogue = catalogue
        self._values: dict[str, str] = {}

    def news(self, key: str, value: Any) -> tuple[str, bool] | None:
        """(the value as JSON, whether ``key`` is an event key), or None: nothing new."""
        spec = self.catalogue.lookup(key)
        event = spec is not None and spec.kind == "event"
        text = json_text(value)
        if not event and self._values.get(key) == text:
            return None
        self._values[key] = text
        return text, event


def device_of(key: str) -> str | None:
    """The device whose health ``key`` is (``/devices/<name>/ok``), or None."""
    if key.startswith(DEVICES_PREFIX) and key.endswith("/ok"):
        return key.removeprefix(DEVICES_PREFIX).removesuffix("/ok")
    return None


class BlackboardNews:
    """A blackboard watcher publishing what each committed write means on ``stream``."""

    def __init__(
        self,
        stream: SessionStream,
        catalogue: KeyCatalogue,
        clock: Clock,
        carried_by: Callable[[Iterable[str]], Carries] = lambda keys: NOTHING,
    ) -> None:
        """``carried_by``: what of a person keys' values are (the blackboard's)."""
        self.stream = stream
        self.carried_by = carried_by
        self.catalogue = catalogue
        self.clock = clock
        self._changed = ChangedKeys(catalogue)
        self._device_ok: dict[str, bool] = {}

    def __call__(self, key: str, value: Any) -> None:
        now = self.clock.now()
        publish = self.stream.publish
        if self.stream.wants(KeyChanged.kind):  # JSON for every write costs: only if read
            news = self._changed.news(key, value)
            if news is not None:
                text, event = news
                carries = self.carried_by((key,))
                publish(KeyChanged(now, key, value, text, event, self._writer(key), carries))
        if key == SPEECH_HEARD:
            publish(Heard(now, str(value)))
        elif key == HAND_SHOWN and isinstance(value, int):
            publish(HandShown(now, value))
        elif key == SPEECH_NOT_LISTENED and isinstance(value, dict):
            publish(
                NotListened(
                    now,
                    float(value.get("from_s", now)),
                    float(value.get("until_s", now)),
                    str(value.get("why", "")),
                )
            )
        device = device_of(key)
        if device is not None:
            ok = bool(value)
            previous = self._device_ok.get(device)
            self._device_ok[device] = ok
            if previous != ok:
                publish(DeviceChanged(now, device, ok, first=previous is None))

    def _writer(self, key: str) -> str:
        if key.startswith(VARIABLES_PREFIX):
            return "trees"
        spec = self.catalogue.lookup(key)
        return spec.writer if spec is not None else ""

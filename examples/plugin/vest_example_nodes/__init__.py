"""Example vest plugin: two node types a YAML tree can use once this package is installed.

- ``IsWarm`` (a condition): is the last temperature reading above a threshold?
- ``Blink`` (an action): flash the face LEDs a few times.

vest finds them through the ``vest.nodes`` entry point group (see pyproject.toml), which
names :func:`register`. After ``pip install -e examples/plugin`` they appear in
``vest nodes`` and can be used in YAML (examples/plugin/trees/warm_greeting.yaml).
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import ClassVar

from engine.nodes import Color, Condition, Integer, Leaf, NodeRegistry, Number, Param, Status
from engine.nodes.context import TreeContext
from engine.services import Job
from engine.services.turns import FACE_LEDS

TEMPERATURE_C = "/sensors/temperature/c"


class IsWarm(Condition):
    """Is the room warm? Looks at the last temperature reading (ReadSensor takes one).

    SUCCESS when /sensors/temperature/c is above ``above_c``; FAILURE when it is not, or
    when the temperature has not been read yet.
    """

    above_c = Param(
        "above_c", Number(-40.0, 125.0, "degC"), 25.0, "warmer than this counts as warm"
    )
    reads: ClassVar = (TEMPERATURE_C,)

    def check(self) -> bool:
        celsius = self.read(TEMPERATURE_C)
        if celsius is None:
            self.feedback_message = "no temperature reading yet"
            return False
        self.feedback_message = f"{celsius:.1f} degC"
        return bool(celsius > self.above_c)


class Blink(Leaf):
    """Blink the face LEDs: ``times`` flashes of ``color``, each ``on_s`` lit, ``off_s`` dark.

    RUNNING while blinking; SUCCESS when the last flash is over; FAILURE when the LED
    service could not light them. Pre-empted (another branch took over), it turns the
    LEDs off.
    """

    color = Param("color", Color(), "white", "a color name (pink, orange, ...) or #RRGGBB")
    times = Param("times", Integer(1, 20), 3, "how many flashes")
    on_s = Param("on_s", Number(0.05, 5.0, "s"), 0.3, "how long each flash stays lit")
    off_s = Param("off_s", Number(0.05, 5.0, "s"), 0.3, "the dark pause between flashes")
    uses = (FACE_LEDS,)  # vest validate names a tree of its priority that lights them too

    def __init__(self, name: str, args: SimpleNamespace, ctx: TreeContext) -> None:
        super().__init__(name, args, ctx)
        self.job: Job | None = None  # the flash being shown, None while dark
        self.flashes_left = 0
        self.dark_until_s = 0.0

    def initialise(self) -> None:
        self.flashes_left = self.times
        self._flash()

    def _flash(self) -> None:
        # The LED service keeps the color for on_s and then turns it off by itself.
        self.flashes_left -= 1
        self.job = self.ctx.actions.set_led(self.color, seconds=self.on_s)

    def update(self) -> Status:
        if self.job is not None:  # lit: wait for the flash to end, never block the tick
            if not self.job.done():
                return Status.RUNNING
            error = self.job.error()
            if error is not None:
                self.feedback_message = f"could not blink: {error}"
                return Status.FAILURE
            self.job = None
            if self.flashes_left == 0:
                self.feedback_message = f"blinked {self.times} times"
                return Status.SUCCESS
            self.dark_until_s = self.now() + self.off_s
        if self.now() < self.dark_until_s:
            return Status.RUNNING
        self._flash()
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.job is not None and not self.job.done():
            self.job.cancel()
            self.ctx.actions.set_led("off")
        self.job = None


def register(registry: NodeRegistry) -> None:
    """The ``vest.nodes`` entry point: add this package's node types to ``registry``."""
    registry.add(IsWarm)
    registry.add(Blink)

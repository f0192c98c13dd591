"""VL53L0X chips on XSHUT lines: switched on one at a time, and brought back when lost.

Every VL53L0X boots at 0x29. On a bus with several, each has its own XSHUT line (low:
hardware standby, off the bus, its address forgotten): at start-up :meth:`XshutChain.start`
puts them all in standby, then switches them on one at a time, initialises each at 0x29
and moves it to its configured address before the next one wakes.

The chain keeps its lines for the whole session. A chip that lost power (a cable pulled
and pushed back) boots at 0x29 again, and one that did not answer at start-up was left in
standby: either way it no longer answers at its address, and nothing but its XSHUT line
can bring it back. Its poller then calls :meth:`XshutChain.reboot`: its line low then
high, the boot time on the clock, init at 0x29 and the move to its address again. One chip
at a time (the chain's lock), with 0x29 claimed on the bus manager meanwhile, and at most
once per :attr:`XshutChain.retry_s` per chip, so a chip that is really gone does not have
its line toggled at every poll.

A chip configured to stay at 0x29 (only the last of a chain may) would answer beside the
one being rebooted: it is held in standby meanwhile, then switched on and initialised
again at 0x29, as at start-up, so its driver carries on.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from engine.clock import Clock
from engine.drivers import vl53l0x
from engine.drivers.bus_errors import describe_exception
from engine.drivers.bus_manager import BusManager
from engine.drivers.gpio import OutputLine
from engine.hardware.config import DeviceConfig, hex_address

T = TypeVar("T")

RETRY_S = 2.0
"""Seconds between two reboots of one chip that keeps not answering (the re-probe interval)."""


class XshutChain:
    """The VL53L0X chips of one bus behind their XSHUT lines, for the whole session.

    ``members`` are the chips in switch-on order with their lines; ``manager`` is the bus
    manager of their bus; waits (boot time, the drivers' own) are slept on ``clock``.
    """

    def __init__(
        self,
        manager: BusManager[Any],
        members: Sequence[tuple[DeviceConfig, OutputLine]],
        clock: Clock,
        *,
        retry_s: float = RETRY_S,
    ) -> None:
        if retry_s <= 0:
            raise ValueError(f"retry_s must be positive, got {retry_s}")
        self.manager = manager
        self.clock = clock
        self.retry_s = retry_s
        self._devices = {device.name: device for device, _ in members}
        self._lines = {device.name: line for device, line in members}
        self._lock = threading.Lock()
        self._next_reboot_s: dict[str, float] = {}
        self.reboots: dict[str, int] = {name: 0 for name in self._devices}
        """How many times each chip was rebooted since start-up."""

    @property
    def names(self) -> list[str]:
        """The chips' device names, in switch-on order."""
        return list(self._devices)

    def __contains__(self, name: object) -> bool:
        return name in self._devices

    def start(self) -> dict[str, str]:
        """Every chip to standby, then each switched on and moved in turn.

        Returns why each chip that did not come up failed, by device name; such a chip is
        left in standby, out of the way of the next, and its poller reboots it later.
        """
        problems: dict[str, str] = {}
        with self._lock:
            for line in self._lines.values():
                line.set(False)  # every chip in standby, forgetting any earlier address
            for name in self._devices:
                try:
                    self._boot(name)
                except Exception as error:
                    problems[name] = (
                        f"did not come up at 0x29 to be moved to "
                        f"{hex_address(self._devices[name].address)}: " + describe_exception(error)
                    )
        return problems

    def may_reboot(self, name: str) -> bool:
        """Whether ``name`` is on the chain and its last reboot is long enough ago."""
        if name not in self._devices:
            return False
        return self.clock.now() >= self._next_reboot_s.get(name, float("-inf"))

    def reboot(self, name: str) -> None:
        """Power-cycle ``name`` through its XSHUT line, init it at 0x29 and move it back.

        Raises what the init or the move raised (the chip is then left in standby).
        """
        if name not in self._devices:
            raise ValueError(f"{name!r} is not on this XSHUT chain ({', '.join(self._devices)})")
        with self._lock:
            self._next_reboot_s[name] = self.clock.now() + self.retry_s
            self.reboots[name] += 1
            resident = self._resident(besides=name)
            self._lines[name].set(False)
            if resident is not None:
                self._lines[resident].set(False)  # it would answer at 0x29 beside this one
            try:
                self._boot(name)
            finally:
                if resident is not None:
                    # If it does not come up, its own poller notices and reboots it in turn.
                    with contextlib.suppress(Exception):
                        self._boot(resident)

    # -- inside ----------------------------------------------------------------------------
    def _resident(self, *, besides: str) -> str | None:
        """The other chip of the chain that lives at 0x29, if any."""
        for name, device in self._devices.items():
            if name != besides and device.address == vl53l0x.DEFAULT_ADDRESS:
                return name
        return None

    def _boot(self, name: str) -> None:
        """Switch ``name`` on, wait its boot time, init it at 0x29 and move it (lock held)."""
        device = self._devices[name]
        line = self._lines[name]
        target = device.address
        assert target is not None
        options = device.options
        clock = self.clock

        def move(raw: Any) -> None:
            sensor = vl53l0x.VL53L0X(raw, address=vl53l0x.DEFAULT_ADDRESS, clock=clock, **options)
            if target != vl53l0x.DEFAULT_ADDRESS:
                sensor.set_address(target)

        line.set(True)
        clock.sleep(vl53l0x.BOOT_TIME_S)
        try:
            self._at_boot_address(move)
        except Exception:
            line.set(False)  # back to standby, off the bus, out of the next chip's way
            raise

    def _at_boot_address(self, work: Callable[[Any], T]) -> T:
        """Run ``work(bus)`` as one transaction with 0x29 claimed on the bus manager.

        0x29 is claimed for the while unless a chip of the chain stays there: that one is
        in standby meanwhile, and its claim is used.
        """
        holder = self.manager.holder(vl53l0x.DEFAULT_ADDRESS)
        if holder is not None:
            return self.manager.call(holder, work)
        handle = self.manager.claim(
            f"VL53L0X start-up on {self.manager.place(None)}", vl53l0x.DEFAULT_ADDRESS
        )
        try:
            return handle.call(work)
        finally:
            handle.release()

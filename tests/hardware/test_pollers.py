"""Pollers: at their rate, onto the blackboard, through a device failing and coming back."""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

import pytest

from engine.clock import Clock, RealClock, VirtualClock
from engine.drivers.bus_manager import BusManager
from engine.files.problems import Mark
from engine.hardware.branching_clock import BranchingClock
from engine.hardware.chips import default_chips
from engine.hardware.config import ChipSpec, DeviceConfig, ForcePad
from engine.hardware.device_health import DeviceHealth
from engine.hardware.pollers import Poller, PollerThreads, make_poller
from engine.hardware.readings import Staged
from engine.hardware.sim_vest import SpiSocket
from engine.sim.i2c_bus import SimI2CBus
from engine.sim.mcp3008 import SimMCP3008
from engine.sim.mpr121 import SimMPR121
from engine.sim.spi_bus import SimSpiDev
from engine.sim.zx_gesture import SimZXGesture

HERE = Mark("test", 1, 1)


class RecordingBoard:
    """A blackboard that keeps what was staged, in order."""

    def __init__(self) -> None:
        self.staged: list[tuple[str, Any, bool]] = []
        self.changed = threading.Event()

    def stage(self, key: str, value: Any) -> None:
        self.staged.append((key, value, False))
        self.changed.set()

    def stage_event(self, key: str, value: Any) -> None:
        self.staged.append((key, value, True))
        self.changed.set()

    def last(self, key: str) -> Any:
        return next(value for k, value, _ in reversed(self.staged) if k == key)


class Bench:
    """One simulated I2C bus and its inline bus manager, on a virtual clock."""

    def __init__(self) -> None:
        self.base = VirtualClock()
        self.clock = BranchingClock(self.base)
        self.bus = SimI2CBus(self.clock)
        self.board = RecordingBoard()
        self.health: dict[str, DeviceHealth] = {}
        self.manager = BusManager(
            self.bus,
            name="1",
            clock=self.clock,
            threaded=False,
            on_status=lambda device, ok: self.health[device].bus_status(ok),
        )

    def poller(self, device: DeviceConfig) -> Poller[Any]:
        self.health[device.name] = DeviceHealth(device.name, self.board)  # type: ignore[arg-type]
        handle = self.manager.claim(device.name, device.address)
        poller = make_poller(
            device,
            handle,
            clock=self.clock,
            blackboard=self.board,  # type: ignore[arg-type]
            health=self.health[device.name],
        )
        poller.connect()  # as at start-up: a chip calibrates on what it senses then
        return poller

    def pretend(
        self,
        name: str,
        read: Callable[[object], list[Staged]],
        *,
        release: Callable[[object], None] | None = None,
    ) -> Poller[object]:
        """A 10 Hz poller of a pretend device whose reads ``read`` answers (its health in
        :attr:`health`)."""
        self.health[name] = DeviceHealth(name, self.board)  # type: ignore[arg-type]
        return Poller(
            name,
            rate_hz=10.0,
            clock=self.clock,
            blackboard=self.board,  # type: ignore[arg-type]
            health=self.health[name],
            connect=object,
            read=read,
            release=release,
        )

    def run(self, poller: Poller[Any], seconds: float, step_s: float = 0.01) -> None:
        """Call the hook now and every ``step_s`` for ``seconds``, as a scheduler would."""
        end = self.base.now() + seconds
        while self.base.now() < end - 1e-9:
            poller(self.base.now())
            self.base.advance(step_s)


@pytest.fixture
def bench() -> Bench:
    return Bench()


def chip_spec(chip: str) -> ChipSpec:
    kind = default_chips().get(chip)
    assert kind is not None
    return kind.spec


TOUCH = DeviceConfig(
    name="touch",
    spec=chip_spec("mpr121"),
    bus="i2c",
    mark=HERE,
    address=0x5A,
    rate_hz=10.0,
    keys={"pads": "/sensors/touch/pads", "any": "/sensors/touch/any"},
    options={"touch_threshold": 12, "release_threshold": 6},
)


def test_a_hook_polls_on_its_own_deadlines_not_every_call(bench: Bench):
    bench.bus.attach(SimMPR121())
    poller = bench.poller(TOUCH)

    bench.run(poller, 1.0, step_s=0.025)  # 40 scheduler steps

    assert poller.polls == 10  # 10 Hz


def test_a_late_hook_skips_the_polls_it_missed(bench: Bench):
    bench.bus.attach(SimMPR121())
    poller = bench.poller(TOUCH)
    poller(bench.base.now())

    bench.base.advance(0.55)
    poller(bench.base.now())

    assert poller.polls == 2
    assert poller.next_due_s == pytest.approx(0.6)


def test_a_touched_pad_is_staged_as_pads_and_any(bench: Bench):
    chip = bench.bus.attach(SimMPR121())
    poller = bench.poller(TOUCH)
    chip.touch(2)  # type: ignore[attr-defined]

    bench.run(poller, 0.1)

    pads = bench.board.last("/sensors/touch/pads")
    assert [pad for pad, on in enumerate(pads) if on] == [2]
    assert bench.board.last("/sensors/touch/any") is True


def test_an_unplugged_chip_goes_offline_rests_its_readings_and_comes_back(bench: Bench):
    chip = bench.bus.attach(SimMPR121())
    poller = bench.poller(TOUCH)
    chip.touch(2)  # type: ignore[attr-defined]
    bench.run(poller, 0.2)
    assert bench.board.last("/sensors/touch/any") is True

    bench.bus.inject("unplugged", 1.0, 0x5A)
    bench.run(poller, 0.5)

    assert bench.board.last("/devices/touch/ok") is False
    assert bench.board.last("/sensors/touch/any") is False
    assert poller.driver is None  # made again once the chip answers

    chip.touch(2, False)  # type: ignore[attr-defined]
    bench.run(poller, 3.0)  # the unplug ends; the re-probe (every 2 s) finds it
    assert bench.board.last("/devices/touch/ok") is True
    chip.touch(7)  # type: ignore[attr-defined]
    bench.run(poller, 0.2)
    assert bench.board.last("/sensors/touch/pads")[7] is True


def test_a_chip_answering_nonsense_is_marked_not_ok_though_the_bus_is_fine(bench: Bench):
    adc = SimMCP3008()
    socket = SpiSocket(adc, bench.clock)
    node = SimSpiDev(socket, 0, 0)
    spi_manager = BusManager(
        node,
        name="0.0",
        kind="SPI",
        clock=bench.clock,
        threaded=False,
        on_status=lambda device, ok: bench.health[device].bus_status(ok),
    )
    device = DeviceConfig(
        name="force",
        spec=chip_spec("mcp3008"),
        bus="spi",
        mark=HERE,
        rate_hz=10.0,
        options={"vref_v": 3.3, "max_speed_hz": 1_000_000},
        pads=(ForcePad("left", 0, "/sensors/force/left_n", ((0.0, 0.0), (3.3, 10.0)), HERE),),
    )
    bench.health["force"] = DeviceHealth("force", bench.board)  # type: ignore[arg-type]
    poller = make_poller(
        device,
        spi_manager.claim("force"),
        clock=bench.clock,
        blackboard=bench.board,  # type: ignore[arg-type]
        health=bench.health["force"],
    )
    adc.set_input_volts(0, 1.65)
    bench.run(poller, 0.1)
    assert bench.board.last("/sensors/force/left_n") == pytest.approx(5.0, abs=0.02)

    socket.inject("unplugged", 1.0)  # MISO pulled high: the null bit is never low
    bench.run(poller, 0.5)

    assert bench.board.last("/devices/force/ok") is False
    assert bench.board.last("/sensors/force/left_n") == 0.0
    assert "null bit" in (poller.last_error or "")
    bench.run(poller, 1.0)
    assert bench.board.last("/devices/force/ok") is True


def test_each_gesture_is_one_event_named_as_the_config_says(bench: Bench):
    zx = bench.bus.attach(SimZXGesture(bench.clock))
    device = DeviceConfig(
        name="gesture",
        spec=chip_spec("zx_gesture"),
        bus="i2c",
        mark=HERE,
        address=0x10,
        rate_hz=20.0,
        keys={"gesture": "/sensors/gesture/last"},
        gesture_names={"swipe_left": "wave", "swipe_up": "swipe_up"},
    )
    poller = bench.poller(device)

    zx.perform("swipe_left")  # type: ignore[attr-defined]
    bench.run(poller, 0.5)
    zx.perform("swipe_up")  # type: ignore[attr-defined]
    bench.run(poller, 0.5)

    events = [(key, value) for key, value, event in bench.board.staged if event]
    assert events == [("/sensors/gesture/last", "wave"), ("/sensors/gesture/last", "swipe_up")]


def touch_poller(
    clock: Clock, board: RecordingBoard, read: Callable[[object], list[Staged]], *, rate_hz: float
) -> Poller[object]:
    """A poller of a pretend touch device whose reads ``read`` answers."""
    return Poller(
        "touch",
        rate_hz=rate_hz,
        clock=clock,
        blackboard=board,  # type: ignore[arg-type]
        health=DeviceHealth("touch", None),
        connect=object,
        read=read,
    )


def test_pollers_on_threads_poll_by_themselves():
    clock = RealClock()
    board = RecordingBoard()
    reads: list[int] = []

    def read(driver: object) -> list[Staged]:
        reads.append(1)
        return [Staged("/sensors/touch/any", True)]

    poller = touch_poller(clock, board, read, rate_hz=50.0)
    threads = PollerThreads([poller], clock)
    threads.start()
    try:
        assert board.changed.wait(timeout=5.0)
    finally:
        threads.stop()

    assert not threads.running
    assert reads and board.last("/sensors/touch/any") is True


def test_a_virtual_clock_drives_poller_threads_poll_by_poll():
    clock = VirtualClock()
    board = RecordingBoard()
    reads: list[float] = []

    def read(driver: object) -> list[Staged]:
        reads.append(clock.now())
        return [Staged("/sensors/touch/any", True)]

    poller = touch_poller(clock, board, read, rate_hz=10.0)
    threads = PollerThreads([poller], clock)
    threads.start(origin_s=0.0)
    try:
        # the first poll is due now; then the thread waits on the virtual clock
        assert clock.until_waiting(1, entered=2)
        assert reads == [0.0]
        clock.advance(0.1)  # one period of virtual time: exactly one more poll
        assert clock.until_waiting(1, entered=3)
        assert len(reads) == 2
    finally:
        threads.stop()
    assert not threads.running


def test_a_driver_bug_is_logged_once_per_failure_streak_not_at_every_poll(
    bench: Bench, caplog: pytest.LogCaptureFixture
):
    broken = True

    def read(driver: object) -> list[Staged]:
        if broken:
            raise ZeroDivisionError("division by zero")  # a bug, not a bus error
        return [Staged("/sensors/touch/any", False)]

    poller = bench.pretend("touch", read)
    with caplog.at_level(logging.INFO, logger="vest.pollers"):
        bench.run(poller, 1.0)  # ten polls, all failing
        broken = False
        bench.run(poller, 0.5)
        broken = True
        bench.run(poller, 0.5)

    errors = [record.getMessage() for record in caplog.records if record.levelno >= logging.ERROR]
    assert errors == ["touch: poll failed with ZeroDivisionError: division by zero"] * 2
    assert poller.failures == 15 and bench.health["touch"].ok is False


def test_a_chip_that_cannot_be_released_at_stop_is_logged_and_the_stop_goes_on(
    bench: Bench, caplog: pytest.LogCaptureFixture
):
    released: list[object] = []

    def release(driver: object) -> None:
        released.append(driver)
        raise OSError(121, "Remote I/O error")  # unplugged since its last poll

    poller = bench.pretend(
        "range_left", lambda driver: [Staged("/sensors/range/left_mm", 250.0)], release=release
    )
    poller.release()  # never connected: nothing to tell
    bench.run(poller, 0.1)
    driver = poller.driver
    with caplog.at_level(logging.WARNING, logger="vest.pollers"):
        poller.release()
        poller.release()  # once only: the driver is gone

    assert released == [driver] and poller.driver is None
    assert [record.getMessage() for record in caplog.records] == [
        "range_left: not released at stop: Remote I/O error (EREMOTEIO, errno 121)"
    ]

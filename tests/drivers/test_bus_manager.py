"""Stories of the bus manager: one owner per bus, priorities, retries, offline devices.

Most stories run the manager in its synchronous mode on a VirtualClock, so retries' backoff
moves virtual time and every run is the same. The threaded stories hold the worker on an
event the test controls; nothing sleeps.
"""

from __future__ import annotations

import errno
import logging
import threading
from collections.abc import Iterator
from concurrent.futures import CancelledError, Future
from typing import Any

import pytest

from engine.clock import VirtualClock
from engine.drivers.bus_errors import (
    AddressConflictError,
    BusClosedError,
    DeviceOfflineError,
    TransactionFailedError,
    errno_in_words,
)
from engine.drivers.bus_manager import (
    BusManager,
    DeviceHandle,
    Priority,
    percentile,
)
from engine.drivers.device_errors import ImplausibleReadingError
from engine.errors import ConfigError, DeviceError
from engine.sim.i2c_bus import RegisterFile, SimI2CBus, SimI2CDevice

WAIT_S = 5.0  # generous bound on waits for the worker thread, so a bug fails instead of hanging
HOLD_S = 300.0
"""How long a transaction holds the bus at most when a story releases it itself: never
reached on a loaded machine, only so a failed story ends."""

TOF_LEFT = 0x29
TOF_RIGHT = 0x30


class ProbeChip(SimI2CDevice):
    """A small sensor: an identity register and a 16-bit big-endian reading.

    Registers auto-increment on reads and writes; writes to the read-only identity
    register are ignored, as on most chips.
    """

    WHO_AM_I = 0x0F
    IDENTITY = 0xA5
    READING = 0x10  # 0x10 high byte, 0x11 low byte

    def __init__(self, address: int, *, identity: int = IDENTITY) -> None:
        super().__init__(address)
        self._registers = RegisterFile()
        self._registers.bytes[self.WHO_AM_I] = identity
        self.level = 0

    @property
    def level(self) -> int:
        high, low = self._registers.bytes[self.READING : self.READING + 2]
        return (high << 8) | low

    @level.setter
    def level(self, value: int) -> None:
        self._registers.bytes[self.READING : self.READING + 2] = value.to_bytes(2, "big")

    def write(self, data: bytes) -> None:
        if not data:
            return
        self._registers.pointer = data[0]
        for value in data[1:]:
            if self._registers.pointer != self.WHO_AM_I:
                self._registers.bytes[self._registers.pointer] = value
            self._registers.advance()

    def read(self, length: int) -> bytes:
        out = bytearray()
        for _ in range(length):
            out.append(self._registers.bytes[self._registers.pointer])
            self._registers.advance()
        return bytes(out)


class RecordingBus(SimI2CBus):
    """A simulated bus that remembers whether someone closed it."""

    def __init__(self, clock: VirtualClock) -> None:
        super().__init__(clock, bus_number=1)
        self.closes = 0

    def close(self) -> None:
        self.closes += 1


def read_level(address: int) -> Any:
    """A transaction: the chip's 16-bit reading, as a driver would read it."""

    def transaction(bus: SimI2CBus) -> int:
        high, low = bus.read_i2c_block_data(address, ProbeChip.READING, 2)
        return (high << 8) | low

    return transaction


def check_identity(address: int) -> Any:
    """A probe: the identity register must answer 0xA5."""

    def probe(bus: SimI2CBus) -> None:
        found = bus.read_byte_data(address, ProbeChip.WHO_AM_I)
        if found != ProbeChip.IDENTITY:
            raise DeviceError(f"chip at 0x{address:02X} answered identity 0x{found:02X}")

    return probe


class Vest:
    """A bus with two chips and a manager, and what the manager reported."""

    def __init__(self, *, threaded: bool = False, **options: Any) -> None:
        self.clock = VirtualClock()
        self.bus = RecordingBus(self.clock)
        self.left_chip = self.bus.attach(ProbeChip(TOF_LEFT))
        self.right_chip = self.bus.attach(ProbeChip(TOF_RIGHT))
        self.statuses: list[tuple[str, bool]] = []
        self.status_changed = threading.Event()
        self.manager: BusManager[SimI2CBus] = BusManager(
            self.bus,
            name="1",
            clock=self.clock,
            threaded=threaded,
            on_status=self._record_status,
            **options,
        )

    def _record_status(self, device: str, ok: bool) -> None:
        self.statuses.append((device, ok))
        self.status_changed.set()

    def claim_left(self, *, probe: bool = True) -> DeviceHandle[SimI2CBus]:
        return self.manager.claim(
            "tof_left", TOF_LEFT, probe=check_identity(TOF_LEFT) if probe else None
        )

    def claim_right(self) -> DeviceHandle[SimI2CBus]:
        return self.manager.claim("tof_right", TOF_RIGHT, probe=check_identity(TOF_RIGHT))


@pytest.fixture
def vest() -> Iterator[Vest]:
    made = Vest()
    yield made
    made.manager.close()


@pytest.fixture
def threaded_vest() -> Iterator[Vest]:
    made = Vest(threaded=True)
    yield made
    made.manager.close()


def fail_three_polls(handle: DeviceHandle[SimI2CBus]) -> None:
    for _ in range(3):
        with pytest.raises(TransactionFailedError):
            handle.submit(read_level(TOF_LEFT)).result()


# -- reading -------------------------------------------------------------------------------
def test_inline_read_returns_the_chips_reading_before_submit_returns(vest: Vest) -> None:
    left = vest.claim_left()
    vest.left_chip.level = 0x1234
    seen_in: list[threading.Thread] = []

    def transaction(bus: SimI2CBus) -> int:
        seen_in.append(threading.current_thread())
        return read_level(TOF_LEFT)(bus)

    future = left.submit(transaction)

    assert future.done()
    assert future.result() == 0x1234
    assert seen_in == [threading.current_thread()]


def test_threaded_submit_runs_on_the_bus_worker(threaded_vest: Vest) -> None:
    left = threaded_vest.claim_left()
    threaded_vest.left_chip.level = 512
    seen_in: list[str] = []

    def transaction(bus: SimI2CBus) -> int:
        seen_in.append(threading.current_thread().name)
        return read_level(TOF_LEFT)(bus)

    assert left.submit(transaction).result(WAIT_S) == 512
    assert seen_in == ["bus-I2C-1"]


def test_a_call_on_an_idle_bus_runs_in_the_callers_thread(threaded_vest: Vest) -> None:
    left = threaded_vest.claim_left()
    threaded_vest.left_chip.level = 513
    seen_in: list[str] = []

    def transaction(bus: SimI2CBus) -> int:
        seen_in.append(threading.current_thread().name)
        return read_level(TOF_LEFT)(bus)

    assert left.call(transaction, timeout_s=WAIT_S) == 513
    assert seen_in == [threading.current_thread().name]


def test_work_queued_while_a_call_holds_the_bus_runs_on_the_worker_after_it(
    threaded_vest: Vest,
) -> None:
    left, right = threaded_vest.claim_left(), threaded_vest.claim_right()
    ran: list[tuple[str, str]] = []
    queued: list[Future[None]] = []

    def note(tag: str) -> Any:
        def transaction(bus: SimI2CBus) -> None:
            ran.append((tag, threading.current_thread().name))

        return transaction

    def call_that_sees_another_driver_submit(bus: SimI2CBus) -> None:
        note("call")(bus)
        # another driver, in another thread, submits while this call holds the bus
        other = threading.Thread(target=lambda: queued.append(right.submit(note("queued"))))
        other.start()
        other.join(WAIT_S)

    left.call(call_that_sees_another_driver_submit, timeout_s=WAIT_S)
    queued[0].result(WAIT_S)

    assert ran == [("call", threading.current_thread().name), ("queued", "bus-I2C-1")]


def test_requests_go_before_queued_polls_and_each_priority_keeps_its_order(
    threaded_vest: Vest,
) -> None:
    left = threaded_vest.claim_left()
    started, release = threading.Event(), threading.Event()
    order: list[str] = []

    def hold_the_bus(bus: SimI2CBus) -> str:
        started.set()
        release.wait(HOLD_S)  # until the story has queued the five
        return "held"

    def tagged(tag: str) -> Any:
        def transaction(bus: SimI2CBus) -> int:
            order.append(tag)
            return read_level(TOF_LEFT)(bus)

        return transaction

    holding = left.submit(hold_the_bus)
    assert started.wait(WAIT_S)
    futures = [
        left.submit(tagged("poll 1")),
        left.submit(tagged("request 1"), priority=Priority.REQUEST),
        left.submit(tagged("poll 2")),
        left.submit(tagged("request 2"), priority=Priority.REQUEST),
        left.submit(tagged("poll 3")),
    ]
    assert threaded_vest.manager.pending == 5
    release.set()

    assert holding.result(WAIT_S) == "held"
    for future in futures:
        future.result(WAIT_S)
    assert order == ["request 1", "request 2", "poll 1", "poll 2", "poll 3"]


def test_a_cancelled_transaction_never_reaches_the_bus(threaded_vest: Vest) -> None:
    left = threaded_vest.claim_left()
    started, release = threading.Event(), threading.Event()
    ran: list[str] = []

    def hold_the_bus(bus: SimI2CBus) -> None:
        started.set()
        release.wait(WAIT_S)

    left.submit(hold_the_bus)
    assert started.wait(WAIT_S)
    cancelled = left.submit(lambda bus: ran.append("cancelled"))
    kept = left.submit(lambda bus: ran.append("kept"))
    assert cancelled.cancel()
    release.set()

    kept.result(WAIT_S)
    assert ran == ["kept"]
    with pytest.raises(CancelledError):
        cancelled.result(0)


def test_transactions_from_many_threads_never_share_the_bus(threaded_vest: Vest) -> None:
    handles = [threaded_vest.claim_left(), threaded_vest.claim_right()]
    threaded_vest.left_chip.level, threaded_vest.right_chip.level = 1000, 2000
    on_bus = [0]
    overlaps: list[int] = []
    answers: list[int] = []

    def exclusive(address: int) -> Any:
        def transaction(bus: SimI2CBus) -> int:
            on_bus[0] += 1
            try:
                if on_bus[0] > 1:
                    overlaps.append(on_bus[0])
                return read_level(address)(bus)
            finally:
                on_bus[0] -= 1

        return transaction

    def driver(index: int) -> None:
        for turn in range(100):
            handle = handles[(index + turn) % 2]
            transaction = exclusive(handle.address or 0)
            if turn % 2:
                answers.append(handle.call(transaction, timeout_s=WAIT_S))
            else:
                answers.append(handle.submit(transaction).result(WAIT_S))

    drivers = [threading.Thread(target=driver, args=(index,)) for index in range(4)]
    for thread in drivers:
        thread.start()
    for thread in drivers:
        thread.join(WAIT_S)

    assert overlaps == []
    assert sorted(set(answers)) == [1000, 2000]
    assert len(answers) == 400


# -- retries -------------------------------------------------------------------------------
def test_a_short_nack_is_retried_with_backoff_then_succeeds(vest: Vest) -> None:
    left = vest.claim_left()
    vest.left_chip.level = 777
    vest.bus.inject("nack", 0.0015, TOF_LEFT)  # 1.5 ms: two attempts fail, the third answers

    assert left.submit(read_level(TOF_LEFT)).result() == 777

    # backoff 1 ms, then 2 ms, slept on the virtual clock
    assert vest.clock.now() == pytest.approx(0.003)
    stats = left.stats()
    assert (stats.transactions, stats.errors, stats.retries) == (1, 0, 2)
    assert stats.online


def test_retries_also_work_on_the_worker_thread(threaded_vest: Vest) -> None:
    left = threaded_vest.claim_left()
    threaded_vest.left_chip.level = 31
    threaded_vest.bus.inject("nack", 0.0015, TOF_LEFT)

    assert left.call(read_level(TOF_LEFT), timeout_s=WAIT_S) == 31
    assert left.stats().retries == 2


def test_a_nack_that_lasts_fails_with_errno_in_words_device_bus_and_address(
    vest: Vest,
) -> None:
    left = vest.claim_left()
    vest.bus.inject("nack", 10.0, TOF_LEFT)

    with pytest.raises(DeviceError) as caught:
        left.submit(read_level(TOF_LEFT)).result()

    error = caught.value
    assert isinstance(error, TransactionFailedError)
    assert str(error) == (
        "tof_left (I2C 0x29 on bus 1): Remote I/O error (EREMOTEIO, errno 121) after 3 attempts"
    )
    assert error.errno == errno.EREMOTEIO
    assert error.attempts == 3
    assert isinstance(error.__cause__, OSError)


@pytest.mark.parametrize(
    ("fault", "words"),
    [
        ("hold", "Connection timed out"),  # a chip holds SDA low: the adapter times out
        ("missing", "No such device or address"),  # nothing answers at the address
    ],
)
def test_bus_faults_are_told_in_words(vest: Vest, fault: str, words: str) -> None:
    left = vest.claim_left()
    if fault == "missing":
        vest.bus.detach(TOF_LEFT)
    else:
        vest.bus.inject(fault, 10.0)

    with pytest.raises(TransactionFailedError, match=words):
        left.submit(read_level(TOF_LEFT)).result()
    assert left.stats().retries == 2


def test_an_error_no_retry_can_fix_is_reported_after_one_attempt(vest: Vest) -> None:
    left = vest.claim_left()

    def forbidden(bus: SimI2CBus) -> None:
        raise OSError(errno.EACCES, "Permission denied")

    with pytest.raises(TransactionFailedError) as caught:
        left.submit(forbidden).result()
    assert str(caught.value) == (
        "tof_left (I2C 0x29 on bus 1): Permission denied (EACCES, errno 13) after 1 attempt"
    )
    assert left.stats().retries == 0


def test_a_driver_bug_reaches_the_caller_unchanged_and_is_not_retried(vest: Vest) -> None:
    left = vest.manager.claim("tof_left", TOF_LEFT)
    bug = ValueError("distance_mm must be 0..2000, got -5")

    def buggy(bus: SimI2CBus) -> None:
        bus.read_byte_data(TOF_LEFT, ProbeChip.WHO_AM_I)
        raise bug

    future = left.submit(buggy)

    assert future.exception() is bug
    assert vest.bus.transfers == 1
    stats = left.stats()
    assert (stats.transactions, stats.errors, stats.retries) == (1, 1, 0)
    assert stats.last_error == "ValueError: distance_mm must be 0..2000, got -5"


def test_driver_bugs_do_not_take_a_device_offline() -> None:
    vest = Vest(offline_after=1)
    left = vest.claim_left()

    for _ in range(3):
        left.submit(lambda bus: int("three"))

    assert left.online
    assert vest.statuses == [("tof_left", True)]


def test_a_transaction_that_submits_to_its_own_bus_is_told_why(vest: Vest) -> None:
    left = vest.claim_left()

    future = left.submit(lambda bus: left.call(read_level(TOF_LEFT)))

    with pytest.raises(RuntimeError, match="it would wait for itself"):
        future.result()


# -- offline and back ----------------------------------------------------------------------
def test_a_device_that_keeps_failing_goes_offline_and_its_polls_fail_fast(vest: Vest) -> None:
    left, right = vest.claim_left(), vest.claim_right()
    vest.right_chip.level = 250
    vest.bus.inject("nack", 10.0, TOF_LEFT)

    fail_three_polls(left)

    assert vest.statuses == [("tof_left", True), ("tof_right", True), ("tof_left", False)]
    transfers = vest.bus.transfers
    with pytest.raises(DeviceOfflineError, match=r"tof_left \(I2C 0x29 on bus 1\) is offline"):
        left.submit(read_level(TOF_LEFT)).result()
    assert vest.bus.transfers == transfers  # refused without touching the bus
    # the other chip on the same bus carries on
    assert right.submit(read_level(TOF_RIGHT)).result() == 250
    assert left.stats().refused == 1


def test_the_failure_that_takes_a_device_offline_says_so(vest: Vest) -> None:
    left = vest.claim_left()
    vest.bus.inject("nack", 10.0, TOF_LEFT)
    for _ in range(2):
        left.submit(read_level(TOF_LEFT))

    with pytest.raises(TransactionFailedError, match="now offline and will be re-probed every 2 s"):
        left.submit(read_level(TOF_LEFT)).result()


def test_an_offline_device_is_back_once_the_fault_clears_and_a_reprobe_is_due(
    vest: Vest,
) -> None:
    left = vest.claim_left()
    vest.left_chip.level = 900
    vest.bus.inject("nack", 3.0, TOF_LEFT)  # a loose connector for 3 s
    fail_three_polls(left)  # 3 polls x 3 ms of backoff: offline at t = 9 ms
    assert not left.online

    # t = 2.1 s: a re-probe is due but the connector is still loose
    vest.clock.advance(2.1 - vest.clock.now())
    with pytest.raises(DeviceOfflineError):
        left.submit(read_level(TOF_LEFT)).result()
    assert left.stats().probes == 1

    # t = 3.5 s: the fault has cleared, but the next re-probe is only due at t = 4.1 s
    vest.clock.advance(1.4)
    transfers = vest.bus.transfers
    with pytest.raises(DeviceOfflineError, match=r"next re-probe in 0\.6 s"):
        left.submit(read_level(TOF_LEFT)).result()
    assert vest.bus.transfers == transfers

    # t = 4.2 s: the re-probe finds the chip, and the poll behind it reads it
    vest.clock.advance(0.7)
    assert left.submit(read_level(TOF_LEFT)).result() == 900
    assert left.online
    assert vest.statuses == [("tof_left", True), ("tof_left", False), ("tof_left", True)]
    stats = left.stats()
    assert (stats.probes, stats.consecutive_failures) == (2, 0)


def test_a_reprobe_with_the_wrong_identity_keeps_the_device_offline(vest: Vest) -> None:
    left = vest.claim_left()
    vest.bus.inject("nack", 0.5, TOF_LEFT)
    fail_three_polls(left)
    # another chip was plugged in at that address meanwhile
    vest.bus.detach(TOF_LEFT)
    vest.bus.attach(ProbeChip(TOF_LEFT, identity=0x33))

    vest.clock.advance(2.5)
    with pytest.raises(DeviceOfflineError):
        left.submit(read_level(TOF_LEFT)).result()
    assert left.stats().last_error == "DeviceError: chip at 0x29 answered identity 0x33"


def test_without_a_probe_the_first_poll_after_the_interval_is_the_probe(vest: Vest) -> None:
    left = vest.claim_left(probe=False)
    vest.left_chip.level = 42
    vest.bus.inject("nack", 1.0, TOF_LEFT)
    fail_three_polls(left)

    vest.clock.advance(1.0)  # fault gone, but no re-probe due yet
    with pytest.raises(DeviceOfflineError):
        left.submit(read_level(TOF_LEFT)).result()

    vest.clock.advance(1.0)
    assert left.submit(read_level(TOF_LEFT)).result() == 42
    assert left.online
    assert left.stats().probes == 1


def test_a_request_to_an_offline_device_tries_the_bus_once(vest: Vest) -> None:
    left = vest.claim_left()
    vest.left_chip.level = 66
    vest.bus.inject("nack", 0.5, TOF_LEFT)
    fail_three_polls(left)
    retries = left.stats().retries

    with pytest.raises(TransactionFailedError, match="after 1 attempt"):
        left.submit(read_level(TOF_LEFT), priority=Priority.REQUEST).result()
    assert left.stats().retries == retries

    # someone asks again once the fault cleared: the answer brings the device back
    vest.clock.advance(0.5)
    assert left.submit(read_level(TOF_LEFT), priority=Priority.REQUEST).result() == 66
    assert vest.statuses[-1] == ("tof_left", True)


def test_the_worker_reprobes_an_offline_device_that_nobody_polls(threaded_vest: Vest) -> None:
    left = threaded_vest.claim_left()
    threaded_vest.bus.inject("nack", 1.0, TOF_LEFT)
    for _ in range(3):
        with pytest.raises(TransactionFailedError):
            left.submit(read_level(TOF_LEFT)).result(WAIT_S)
    assert threaded_vest.statuses[-1] == ("tof_left", False)
    threaded_vest.status_changed.clear()

    threaded_vest.clock.advance(2.5)  # the worker waits on this clock: advancing wakes it

    assert threaded_vest.status_changed.wait(WAIT_S)
    assert threaded_vest.statuses[-1] == ("tof_left", True)


def test_the_threaded_worker_waits_for_a_reprobe_on_the_virtual_clock(
    threaded_vest: Vest,
) -> None:
    left = threaded_vest.claim_left()
    threaded_vest.bus.inject("nack", 1.0, TOF_LEFT)  # a loose connector for 1 s
    for _ in range(3):
        with pytest.raises(TransactionFailedError):
            left.submit(read_level(TOF_LEFT)).result(WAIT_S)
    assert threaded_vest.statuses[-1] == ("tof_left", False)  # re-probe due 2 s later
    threaded_vest.status_changed.clear()

    # The worker waits on the virtual clock; one second later nothing is due yet.
    assert threaded_vest.clock.until_waiting(1)
    threaded_vest.clock.advance(1.0)
    assert threaded_vest.clock.until_waiting(1)
    assert left.stats().probes == 0

    # Past the re-probe's time the worker wakes by itself and finds the chip again.
    threaded_vest.clock.advance(1.5)
    assert threaded_vest.status_changed.wait(WAIT_S)
    assert threaded_vest.statuses[-1] == ("tof_left", True)
    assert left.stats().probes == 1


def test_a_failing_status_callback_does_not_stop_the_bus(caplog: pytest.LogCaptureFixture) -> None:
    clock = VirtualClock()
    bus = SimI2CBus(clock)
    bus.attach(ProbeChip(TOF_LEFT))

    def broken(device: str, ok: bool) -> None:
        raise KeyError("/devices/tof_left/ok")

    manager: BusManager[SimI2CBus] = BusManager(
        bus, name="1", clock=clock, threaded=False, on_status=broken
    )
    with caplog.at_level(logging.ERROR):
        left = manager.claim("tof_left", TOF_LEFT)
    assert left.submit(read_level(TOF_LEFT)).result() == 0
    assert "on_status('tof_left', True) raised" in caplog.text


# -- claims --------------------------------------------------------------------------------
def test_two_drivers_on_one_address_are_told_who_holds_it(vest: Vest) -> None:
    vest.claim_left()

    with pytest.raises(AddressConflictError) as caught:
        vest.manager.claim("tof_center", TOF_LEFT)

    assert str(caught.value) == "I2C 0x29 on bus 1 is already used by tof_left"
    assert isinstance(caught.value, ConfigError)


def test_one_name_cannot_claim_two_addresses(vest: Vest) -> None:
    vest.claim_left()

    with pytest.raises(AddressConflictError, match="'tof_left' is already claimed at I2C 0x29"):
        vest.manager.claim("tof_left", TOF_RIGHT)


def test_a_claim_of_the_whole_bus_excludes_every_other(vest: Vest) -> None:
    serial: BusManager[SimI2CBus] = BusManager(
        vest.bus, name="/dev/ttyACM0", clock=vest.clock, kind="serial", threaded=False
    )
    serial.claim("maestro")

    with pytest.raises(AddressConflictError) as caught:
        serial.claim("other", 0x0C)
    assert str(caught.value) == "serial bus /dev/ttyACM0 is already used by maestro"


def test_a_released_address_can_be_claimed_again(vest: Vest) -> None:
    vest.claim_left().release()

    center = vest.manager.claim("tof_center", TOF_LEFT)

    assert vest.manager.holder(TOF_LEFT) == "tof_center"
    assert center.submit(read_level(TOF_LEFT)).result() == 0


def test_submitting_for_an_unclaimed_device_is_a_programming_error(vest: Vest) -> None:
    with pytest.raises(ValueError, match="'tof_left' has not claimed an address on I2C bus 1"):
        vest.manager.submit("tof_left", read_level(TOF_LEFT))


# -- statistics ----------------------------------------------------------------------------
def test_statistics_count_transactions_errors_and_retries_per_device(vest: Vest) -> None:
    left, right = vest.claim_left(), vest.claim_right()
    for _ in range(5):
        left.submit(read_level(TOF_LEFT)).result()
    vest.bus.inject("nack", 0.0015, TOF_LEFT)
    left.submit(read_level(TOF_LEFT)).result()  # two retries, then success
    vest.bus.inject("nack", 1.0, TOF_RIGHT)
    right.submit(read_level(TOF_RIGHT)).exception()  # fails after three attempts

    stats = vest.manager.stats()

    assert set(stats) == {"tof_left", "tof_right"}
    left_stats, right_stats = stats["tof_left"], stats["tof_right"]
    assert (left_stats.transactions, left_stats.errors, left_stats.retries) == (6, 0, 2)
    assert (right_stats.transactions, right_stats.errors, right_stats.retries) == (1, 1, 2)
    assert left_stats.last_error is None
    assert right_stats.last_error == "Remote I/O error (EREMOTEIO, errno 121)"
    assert left_stats.online and right_stats.online
    assert (right_stats.bus, right_stats.address) == ("1", TOF_RIGHT)
    assert 0 < left_stats.latency_p50_us <= left_stats.latency_p99_us
    assert left_stats.latency_p99_us <= left_stats.latency_max_us


def test_percentiles_are_nearest_rank() -> None:
    values = [float(v) for v in range(1, 101)]
    assert percentile(values, 0.5) == 50.0
    assert percentile(values, 0.99) == 99.0
    assert percentile(values, 1.0) == 100.0
    assert percentile([], 0.5) == 0.0
    with pytest.raises(ValueError, match="got 99"):
        percentile(values, 99)


def test_errno_words_name_the_code() -> None:
    assert errno_in_words(errno.EIO) == "Input/output error (EIO, errno 5)"


# -- closing -------------------------------------------------------------------------------
def test_close_fails_queued_transactions_and_leaves_the_bus_open() -> None:
    vest = Vest(threaded=True)
    left = vest.claim_left()
    started, release = threading.Event(), threading.Event()

    def hold_the_bus(bus: SimI2CBus) -> str:
        started.set()
        release.wait(WAIT_S)
        return "finished"

    running = left.submit(hold_the_bus)
    assert started.wait(WAIT_S)
    queued = [left.submit(read_level(TOF_LEFT)) for _ in range(3)]
    closer = threading.Thread(target=vest.manager.close)
    closer.start()

    # the queued ones fail at once, while the running one is still on the bus
    for future in queued:
        error = future.exception(WAIT_S)
        assert isinstance(error, BusClosedError)
        assert str(error) == "I2C bus 1 was closed before tof_left's transaction ran"
    assert not running.done()
    release.set()
    closer.join(WAIT_S)

    assert running.result(WAIT_S) == "finished"
    assert vest.bus.closes == 0
    late: Future[int] = left.submit(read_level(TOF_LEFT))
    with pytest.raises(BusClosedError, match="I2C bus 1 is closed"):
        late.result(0)


def test_a_closed_inline_manager_refuses_transactions(vest: Vest) -> None:
    left = vest.claim_left()
    with vest.manager:
        pass

    with pytest.raises(BusClosedError):
        left.submit(read_level(TOF_LEFT)).result()
    assert vest.bus.closes == 0


def test_options_out_of_range_are_refused_with_the_value() -> None:
    clock = VirtualClock()
    with pytest.raises(ValueError, match="got -1"):
        BusManager(SimI2CBus(clock), name="1", clock=clock, threaded=False, retries=-1)
    with pytest.raises(ValueError, match="got 0"):
        BusManager(SimI2CBus(clock), name="1", clock=clock, threaded=False, offline_after=0)


# -- implausible readings ------------------------------------------------------------------
def test_a_reading_the_driver_refuses_is_counted_as_implausible_and_never_returned(
    vest: Vest,
) -> None:
    left = vest.claim_left()
    vest.left_chip.level = 0xFFFF  # beyond anything this chip can measure

    def read_checked(bus: SimI2CBus) -> int:
        level = read_level(TOF_LEFT)(bus)
        if level > 4000:
            raise ImplausibleReadingError(
                chip="probe chip",
                place="I2C 0x29",
                what="level",
                value=str(level),
                plausible="0..4000",
            )
        return level

    with pytest.raises(ImplausibleReadingError, match="level 65535"):
        left.submit(read_checked).result()
    stats = left.stats()
    assert (stats.implausible, stats.errors) == (1, 1)
    assert stats.last_error is not None and "level 65535" in stats.last_error


def test_a_poller_reports_a_refused_reading_found_after_its_transactions(vest: Vest) -> None:
    left = vest.claim_left()
    assert left.submit(read_level(TOF_LEFT)).result() == 0
    left.note_implausible(
        ImplausibleReadingError(
            chip="probe chip", place="I2C 0x29", what="level", value="9999", plausible="0..4000"
        )
    )
    stats = left.stats()
    assert (stats.transactions, stats.errors, stats.implausible) == (1, 1, 1)
    assert left.online

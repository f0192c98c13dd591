"""What the robot publishes reaches every page's stream: publishing never waits and costs
the same for one page or many, each page reads on the event loop from its own place, and a
page that falls behind is told so instead of slowing anyone."""

from __future__ import annotations

import asyncio
import threading
from typing import Any

from engine.clock import VirtualClock
from engine.web.broadcast import Broadcast, Reader, Taken


def items(taken: Taken[Any] | None) -> tuple[list[object], bool] | None:
    return None if taken is None else ([p.item for p in taken.items], taken.overflowed)


def read(broadcast: Broadcast[Any], reader: Reader) -> tuple[list[object], bool] | None:
    return items(asyncio.run(broadcast.take(reader, 15.0)))


def test_each_page_reads_what_was_published_since_it_came_in_order() -> None:
    broadcast: Broadcast[int] = Broadcast(VirtualClock(), capacity=10)
    broadcast.publish(0)  # before the first page came
    first = broadcast.reader()
    broadcast.publish(1)
    second = broadcast.reader()
    broadcast.publish(2)
    assert read(broadcast, first) == ([1, 2], False)
    assert read(broadcast, second) == ([2], False)


def test_a_page_that_fell_behind_keeps_the_newest_and_hears_it_lost_some() -> None:
    broadcast: Broadcast[int] = Broadcast(VirtualClock(), capacity=3)
    slow, keeping_up = broadcast.reader(), broadcast.reader()
    for change in range(7):
        broadcast.publish(change)  # never waits, however far behind a page is
    assert read(broadcast, keeping_up) == ([4, 5, 6], True)
    for change in range(7, 10):
        broadcast.publish(change)
    assert read(broadcast, slow) == ([7, 8, 9], True)
    assert read(broadcast, keeping_up) == ([7, 8, 9], False)


def test_a_change_s_text_is_made_once_for_every_page() -> None:
    broadcast: Broadcast[dict[str, int]] = Broadcast(VirtualClock(), capacity=3)
    pages = [broadcast.reader() for _ in range(50)]
    broadcast.publish({"tick": 1})
    made: list[str] = []

    def text_of(change: dict[str, int]) -> str:
        made.append("made")
        return str(change)

    for page in pages:
        taken = asyncio.run(broadcast.take(page, 15.0))
        assert taken is not None and taken.items[0].text(text_of) == "{'tick': 1}"
    assert made == ["made"]


def test_waiting_pages_wake_when_the_robot_publishes_from_its_own_thread() -> None:
    clock = VirtualClock()
    broadcast: Broadcast[str] = Broadcast(clock, capacity=10)
    pages = [broadcast.reader() for _ in range(3)]

    def robot() -> None:
        assert clock.until_waiting(3)  # every page waits (holding no thread)
        broadcast.publish("hug")

    async def watch() -> list[tuple[list[object], bool] | None]:
        taken = await asyncio.gather(*(broadcast.take(page, 15.0) for page in pages))
        return [items(one) for one in taken]

    giver = threading.Thread(target=robot)
    giver.start()
    seen = asyncio.run(watch())
    giver.join()
    assert seen == [(["hug"], False)] * 3  # the clock never moved: the publish woke them


def test_nothing_for_a_while_is_an_empty_read_and_the_end_ends_every_stream() -> None:
    clock = VirtualClock()
    broadcast: Broadcast[str] = Broadcast(clock, capacity=10)
    page = broadcast.reader()

    def time_passes_then_the_session_ends() -> None:
        assert clock.until_waiting(1)
        clock.advance(15.0)  # the page's keep-alive is due
        assert clock.until_waiting(1, entered=2)
        broadcast.publish("end")
        broadcast.close()

    async def watch() -> list[Any]:
        return [await broadcast.take(page, 15.0) for _ in range(3)]

    other = threading.Thread(target=time_passes_then_the_session_ends)
    other.start()
    taken = asyncio.run(watch())
    other.join()
    assert [items(one) for one in taken] == [([], False), (["end"], False), None]
    broadcast.publish("late")  # nothing is published after the end
    assert read(broadcast, broadcast.reader()) is None

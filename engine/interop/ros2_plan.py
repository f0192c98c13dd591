"""Where a run's ROS 2 graph is (``vest run --ros2``): read by the composition root and
the bridge, imports neither Zenoh nor rosbags (the ros2 extra)."""

from __future__ import annotations

from dataclasses import dataclass

ROUTER = "tcp/127.0.0.1:7447"
"""Where rmw_zenoh's router (``ros2 run rmw_zenoh_cpp rmw_zenohd``) listens by default."""


@dataclass(frozen=True)
class Ros2Plan:
    """The graph's Zenoh router, or a Zenoh config file in its place; the ROS domain;
    whether commands are taken from it."""

    router: str = ROUTER
    domain: int = 0
    commands: bool = False
    config_file: str | None = None

"""Where a run's ROS 2 graph is (``vest run --ros2``): read by the composition root and
the bridge, imports neither Zenoh nor rosbags (the ros2 extra)."""

from __future__ import annotations

import re
from dataclasses import dataclass

ROUTER = "tcp/127.0.0.1:7447"
"""Where rmw_zenoh's router (``ros2 run rmw_zenoh_cpp rmw_zenohd``) listens by default."""


@dataclass(frozen=True)
class Ros2Plan:
    """The graph's Zenoh router, or a Zenoh config file in its place; the ROS domain;
    whether commands are taken from it; the robot's ``namespace`` ('' for the root: its
    node is then ``/vest``, else ``/<namespace>/vest``, and its topics follow)."""

    router: str = ROUTER
    domain: int = 0
    commands: bool = False
    config_file: str | None = None
    namespace: str = ""

    @property
    def prefix(self) -> str:
        """What comes before ``/vest`` in the node's and the topics' names."""
        return f"/{self.namespace}" if self.namespace else ""


_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def namespace_problem(namespace: str) -> str | None:
    """Why ``namespace`` is not a ROS 2 namespace (None when it is): names of letters,
    digits and underscores, not starting with a digit, joined by ``/``."""
    if namespace.strip("/") == "":  # '' or '/': the root
        return None
    parts = namespace.strip("/").split("/")
    bad = next((part for part in parts if not _NAME.fullmatch(part)), None)
    if bad is None and "__" not in namespace:
        return None
    return (
        f"{namespace!r} is not a ROS 2 namespace: letters, digits and underscores, not "
        "starting with a digit, no double underscore, parts joined by /"
    )


def namespace_from(robot_name: str) -> str:
    """A ROS 2 namespace made from a robot's name (``hbs-2`` -> ``hbs_2``; a name with no
    letter or digit -> ``robot``). Names that differ only in other characters give the same
    namespace: give such robots --ros2-namespace."""
    name = re.sub(r"[^A-Za-z0-9_]", "_", robot_name)
    name = re.sub(r"_+", "_", name).strip("_") or "robot"
    return f"r{name}" if name[:1].isdigit() else name

"""A picture of the vest in text: where each named touch pad and force pad sits.

Pads named after a place the picture knows (``left_shoulder``, ``middle_back``, ``chest``,
...) are drawn there, with their electrode (touch) or channel (force); any other name is
listed under the picture. The robot's left is on the left in both views (the front is
drawn as if seen through the robot), so a therapist never has to mirror it.
"""

from __future__ import annotations

from engine.hardware.config import RobotConfig
from engine.hardware.touch_pads import pad_names

CELL = 20
PLACES: dict[str, tuple[str, int, int]] = {
    # name: (view, row, column); columns are the robot's left, middle, right
    "left_shoulder": ("back", 0, 0),
    "neck": ("back", 0, 1),
    "right_shoulder": ("back", 0, 2),
    "upper_back": ("back", 1, 1),
    "left_back": ("back", 2, 0),
    "middle_back": ("back", 2, 1),
    "right_back": ("back", 2, 2),
    "lower_back": ("back", 3, 1),
    "left_collar": ("front", 0, 0),
    "right_collar": ("front", 0, 2),
    "chest": ("front", 1, 1),
    "left_chest": ("front", 1, 0),
    "right_chest": ("front", 1, 2),
    "belly": ("front", 2, 1),
    "left_arm": ("front", 3, 0),
    "right_arm": ("front", 3, 2),
    "left": ("front", 2, 0),  # the force pads of the hug, on the sides
    "right": ("front", 2, 2),
}
ROWS = 4


def vest_picture(config: RobotConfig) -> str:
    """The vest of ``config`` as text: touch pads with ``[electrode]``, force pads with
    ``(N, channel)``, and the names the picture has no place for."""
    labels: dict[str, list[str]] = {}
    elsewhere: list[str] = []
    for touch in config.with_role("touch"):
        for electrode, name in enumerate(pad_names(touch)):
            labels.setdefault(name, []).append(f"{name} [{electrode}]")
    for force in config.with_role("force"):
        for pad in force.pads:
            labels.setdefault(pad.name, []).append(f"{pad.name} (N, ch {pad.channel})")
    grids: dict[str, list[list[str]]] = {
        view: [[""] * 3 for _ in range(ROWS)] for view in ("back", "front")
    }
    for name, shown in labels.items():
        place = PLACES.get(name)
        if place is None or grids[place[0]][place[1]][place[2]]:
            elsewhere += shown
            continue
        view, row, column = place
        grids[view][row][column] = " / ".join(shown)
    width = CELL * 3 + 2
    lines = [
        f"The vest of {config.path}: touch pads [electrode], force pads (N, channel).",
        "The robot's left is on the left in both views.",
    ]
    for view in ("back", "front"):
        lines += ["", f"{view.upper():^{width + 2}}", f" {'_' * width}"]
        lines += [f"|{_row(cells)}|" for cells in grids[view]]
        lines.append(f"|{'_' * width}|")
    if elsewhere:
        lines += ["", "Elsewhere on the vest: " + ", ".join(elsewhere)]
    if not labels:
        lines += ["", "This robot has no touch or force pads."]
    return "\n".join(lines) + "\n"


def _row(cells: list[str]) -> str:
    return " " + "".join(f"{_fit(cell):^{CELL}}" for cell in cells) + " "


def _fit(text: str) -> str:
    return text if len(text) <= CELL - 1 else text[: CELL - 2] + "~"

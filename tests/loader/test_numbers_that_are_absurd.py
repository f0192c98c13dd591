"""Numbers that YAML allows but no robot means: every rate, duration, speed and format
width has bounds, checked when the file loads, with the place and the bounds."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.files.problems import LoadError
from engine.loader.tree_file import TreeLoader
from engine.nodes.registry import default_registry
from engine.scenario.scenario_file import load_scenario


def tree_problems(tmp_path: Path, root: str) -> list[str]:
    path = tmp_path / "tree.yaml"
    path.write_text("name: t\nrate_hz: 10\nroot:\n" + textwrap.indent(root, "  "))
    with pytest.raises(LoadError) as caught:
        TreeLoader(default_registry(plugins=False), default_catalogue(), root_dir=tmp_path).load(
            path
        )
    return [str(problem) for problem in caught.value.problems]


@pytest.mark.parametrize(
    ("node", "message"),
    [
        ("Wait: {seconds: 1.0e+300}", "'seconds' must be at most 86400, got 1e+300"),
        ("SetLed: {color: pink, seconds: 1.0e+300}", "'seconds' must be at most 86400"),
        ("Cooldown: {seconds: 1.0e+9, child: {Wait: {seconds: 1}}}", "must be at most 86400"),
        ("Timeout: {seconds: -1, child: {Wait: {seconds: 1}}}", "must be at least 0, got -1"),
        ("MoveServo: {joint: neck, angle_deg: 10, speed_dps: 1.0e+12}", "at most 10000"),
        ("LookToward: {max_mm: 1.0e+200}", "'max_mm' must be at most 100000"),
        ("Wait: {seconds: .nan}", "'seconds' must be a finite number, got nan"),
    ],
)
def test_a_duration_speed_or_distance_no_robot_means_is_refused(
    tmp_path: Path, node: str, message: str
) -> None:
    [problem] = tree_problems(tmp_path, node + "\n")
    assert problem.startswith("tree.yaml:4:")
    assert message in problem


@pytest.mark.parametrize(
    "spec",
    [">99999999999", ">900000000", ".101f", "0>1000", "^" + "9" * 400],
)
def test_a_format_width_or_precision_past_100_is_refused_at_load(tmp_path: Path, spec: str) -> None:
    [problem] = tree_problems(tmp_path, f'Say: {{text: "It is {{temperature_f:{spec}}}"}}\n')
    assert "tree.yaml:4:" in problem
    assert "characters (widths and precisions go up to 100" in problem


@pytest.mark.parametrize("spec", [">10", ".1f", "0>5", "^100", ".0f"])
def test_a_format_within_bounds_loads(tmp_path: Path, spec: str) -> None:
    path = tmp_path / "tree.yaml"
    path.write_text(f'rate_hz: 10\nroot:\n  Say: {{text: "It is {{temperature_f:{spec}}}"}}\n')
    loaded = TreeLoader(default_registry(plugins=False), default_catalogue()).load(path)
    assert loaded.rate_hz == 10.0


@pytest.mark.parametrize(
    ("event", "message"),
    [
        ("{at: 1.0e+300, touch: {pad: 3}}", "'at' must be at most 86400"),
        ("{at: 1, touch: {pad: 3, seconds: 1.0e+300}}", "'seconds' must be at most 3600"),
    ],
)
def test_a_scenario_time_no_session_lasts_is_refused(
    tmp_path: Path, event: str, message: str
) -> None:
    path = tmp_path / "s.yaml"
    path.write_text(f"duration_s: 10\nevents:\n  - {event}\n")
    with pytest.raises(LoadError) as caught:
        load_scenario(path)
    assert any(message in str(problem) for problem in caught.value.problems)

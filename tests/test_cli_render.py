"""`vest render`: a tree drawn as ascii, dot, svg or png, labelled with its parameters."""

import shutil
from pathlib import Path

from engine.cli import main

ROOT = Path(__file__).resolve().parents[1]


def test_ascii_render_reads_like_the_yaml(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["render", "trees/hug.yaml"]) == 0
    assert capsys.readouterr().out == (
        "hug (20 Hz)\n"
        "`-- [->] Sequence\n"
        "    |-- Check key=/sensors/force/left_n above=3.0\n"
        "    |-- Check key=/sensors/force/right_n above=3.0\n"
        "    `-- Cooldown seconds=10.0\n"
        "        `-- [=>] Parallel\n"
        "            |-- SetLed color=pink seconds=2.0\n"
        '            `-- Say text="I love hugs!" volume=0.8\n'
    )


def test_a_profile_shows_in_the_render(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["render", "trees/hug.yaml", "--profile", "trees/profiles/child.yaml"]) == 0
    assert "above=2.0" in capsys.readouterr().out


def test_dot_render_has_one_graph_node_per_tree_node(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["render", "trees/wave_greeting.yaml", "--format", "dot"]) == 0
    dot = capsys.readouterr().out
    assert dot.startswith('digraph "wave_greeting" {')
    # Sequence, OnEvent, Cooldown, the subtree's Parallel, SetLed and Say
    assert dot.count("label=") == 6 + 1 + 2 + 4  # the title, a subtree frame, the legend


def test_svg_render_needs_graphviz_and_says_so_when_it_is_missing(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(ROOT)
    out = tmp_path / "hug.svg"
    code = main(["render", "trees/hug.yaml", "--format", "svg", "-o", str(out)])
    if shutil.which("dot"):
        assert code == 0
        assert "<svg" in out.read_text()
        assert "I love hugs!" in out.read_text()
    else:
        assert code == 3
        assert "apt-get install graphviz" in capsys.readouterr().err


def test_png_render_writes_a_png_file(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    out = tmp_path / "hug.png"
    code = main(["render", "trees/hug.yaml", "--format", "png", "-o", str(out)])
    if shutil.which("dot"):
        assert code == 0
        assert out.read_bytes().startswith(b"\x89PNG")
    else:
        assert code == 3


def test_rendering_a_broken_tree_lists_its_problems(tmp_path, capsys):
    broken = tmp_path / "broken.yaml"
    broken.write_text("root:\n  Sequence:\n    - Sya: {text: hi}\n")
    assert main(["render", str(broken)]) == 1
    assert "broken.yaml:3:7: unknown node type 'Sya' (did you mean 'Say'?)" in (
        capsys.readouterr().err
    )


def test_an_output_file_that_cannot_be_written_is_named_with_the_reason(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["render", "trees/hug.yaml", "-o", "/nonexistent/hug.txt"]) == 1
    err = capsys.readouterr().err
    assert "-o /nonexistent/hug.txt: cannot write the drawing (No such file or directory)" in err


def test_a_drawing_speaks_plainly_frames_subtrees_and_has_a_legend(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["render", "trees/wave_greeting.yaml", "--format", "dot"]) == 0
    dot = capsys.readouterr().out
    assert 'label="in order"' in dot  # a Sequence
    assert 'label="at the same time"' in dot  # the subtree's Parallel
    assert 'label="not again for 2 s after acting"' in dot  # the Cooldown
    assert 'label="parts/greet.yaml"' in dot  # the subtree, framed
    assert "cluster_legend" in dot and "a question (yes / no)" in dot
    assert "(10 times a second, priority 30)" in dot


def test_a_wide_tree_is_laid_out_left_to_right(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["render", "trees/finger_game.yaml", "--format", "dot"]) == 0
    assert "rankdir=LR" in capsys.readouterr().out

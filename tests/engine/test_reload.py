"""Hot reload: an edited tree is swapped in between ticks; a broken edit keeps the old one."""

import os
import textwrap

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import default_catalogue
from engine.clock import VirtualClock
from engine.runtime.reload import TreeReloader
from engine.runtime.robot import Robot, load_behaviors
from engine.services.simulated import simulated_services
from engine.session.events import TreeReloaded
from engine.session.stream import EventCollector

GREETER = """\
    name: greeter
    rate_hz: 10
    root:
      Sequence:
        - Check: {key: /sensors/touch/any, equals: true}
        - Say: {text: "PHRASE"}
    """


def edit(path, text, bump):
    path.write_text(textwrap.dedent(text))
    stat = path.stat()
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + bump * 1_000_000_000))


def start(tmp_path):
    tree_file = tmp_path / "greeter.yaml"
    edit(tree_file, GREETER.replace("PHRASE", "Hello"), 0)
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    behaviors = load_behaviors([tmp_path])
    robot = Robot(behaviors, clock=clock, services=simulated_services(clock), blackboard=board)
    reports = []
    reloader = TreeReloader(
        behaviors.loader,
        robot.trees,
        clock,
        check_every_s=1.0,
        on_reload=lambda name, error: reports.append((name, error)),
    )
    robot.scheduler.add_hook(reloader)
    board.set("/sensors/touch/any", True)
    return robot, tree_file, reports


def said(robot):
    return [r.args["text"] for r in robot.action_log.records]


def test_a_changed_phrase_is_spoken_after_the_next_reload_check(tmp_path):
    robot, tree_file, reports = start(tmp_path)
    robot.scheduler.run(until_s=0.05)
    edit(tree_file, GREETER.replace("PHRASE", "Good morning"), 1)
    robot.scheduler.run(until_s=1.05)
    assert said(robot)[0] == "Hello"
    assert said(robot)[-1] == "Good morning"
    assert reports == [("greeter", None)]
    assert robot.trees[0].stats.ticks == 11  # statistics survive the swap


def test_a_broken_edit_keeps_the_running_tree_and_is_reported_once(tmp_path):
    robot, tree_file, reports = start(tmp_path)
    edit(tree_file, GREETER.replace("Say", "Sya"), 1)
    robot.scheduler.run(until_s=3.0)
    assert set(said(robot)) == {"Hello"}
    assert len(reports) == 1
    name, error = reports[0]
    assert name == "greeter"
    assert "greeter.yaml:6:7: unknown node type 'Sya' (did you mean 'Say'?)" in str(error)
    edit(tree_file, GREETER.replace("PHRASE", "Fixed"), 2)
    robot.scheduler.run(until_s=4.0)
    assert said(robot)[-1] == "Fixed"


def test_a_rename_while_running_is_refused_and_the_tree_keeps_its_name(tmp_path):
    robot, tree_file, reports = start(tmp_path)
    edit(tree_file, GREETER.replace("name: greeter", "name: welcomer"), 1)
    robot.scheduler.run(until_s=1.5)
    assert robot.trees[0].name == "greeter"
    assert "renamed 'greeter' -> 'welcomer' while running" in str(reports[0][1])


def test_fixing_a_subtree_that_a_refused_edit_added_reloads_the_tree(tmp_path):
    robot, tree_file, reports = start(tmp_path)
    parts = tmp_path / "parts"
    parts.mkdir()
    edit(parts / "hello.yaml", "root:\n  Say: {txt: broken}\n", 0)
    with_subtree = GREETER.replace('- Say: {text: "PHRASE"}', "- Subtree: {file: parts/hello.yaml}")
    edit(tree_file, with_subtree, 1)
    robot.scheduler.run(until_s=1.5)
    assert reports[-1][1] is not None  # refused: the subtree is broken
    edit(parts / "hello.yaml", 'root:\n  Say: {text: "From the part"}\n', 2)
    robot.scheduler.run(until_s=3.5)
    assert reports[-1] == ("greeter", None)
    assert said(robot)[-1] == "From the part"


def test_a_reload_that_crashes_while_building_keeps_the_running_tree(tmp_path, monkeypatch):
    robot, tree_file, reports = start(tmp_path)
    from engine.loader.tree_definition import TreeDefinition

    def broken_build(self, ctx):
        raise RuntimeError("disk on fire")

    edit(tree_file, GREETER.replace("PHRASE", "Changed"), 1)
    monkeypatch.setattr(TreeDefinition, "build", broken_build)
    robot.scheduler.run(until_s=1.5)
    assert set(said(robot)) == {"Hello"}
    assert "could not reload: RuntimeError: disk on fire" in str(reports[0][1])


def test_on_its_own_thread_the_reloader_prepares_beside_the_ticks_and_swaps_between_them(
    tmp_path,
):
    robot, tree_file, reports = start(tmp_path)
    clock = robot.scheduler.clock
    [reloader] = [hook for hook in robot.scheduler.hooks if isinstance(hook, TreeReloader)]
    reloader.start()
    try:
        assert clock.until_waiting(1)  # the worker waits for its next check
        edit(tree_file, GREETER.replace("PHRASE", "From the worker"), 1)
        clock.advance(1.0)  # the worker's check is due: it loads and builds the new tree
        assert clock.until_waiting(1, entered=2)  # ... and waits again: the new tree is ready
        assert robot.trees[0].definition.root.children[1].args["text"].source == "Hello"
        reloader(clock.now())  # the scheduler's hook swaps it in between ticks
    finally:
        reloader.stop()
    assert reports == [("greeter", None)]
    robot.scheduler.run(until_s=clock.now() + 0.1)
    assert said(robot)[-1] == "From the worker"


def test_only_the_files_a_tree_uses_are_watched_never_its_whole_folder(tmp_path):
    robot, tree_file, _ = start(tmp_path)
    for i in range(50):  # a busy folder: none of these is read at a check
        (tmp_path / f"unrelated_{i}.yaml").write_text("not: a tree\n")
    [reloader] = [hook for hook in robot.scheduler.hooks if isinstance(hook, TreeReloader)]
    edit(tree_file, GREETER.replace("Say", "Sya"), 1)
    reloader.check()
    assert sorted(p.name for p in reloader._stamps[tree_file]) == ["greeter.yaml"]


def test_creating_the_subtree_a_refused_edit_named_reloads_the_tree(tmp_path):
    robot, tree_file, reports = start(tmp_path)
    edit(tree_file, GREETER.replace('- Say: {text: "PHRASE"}', "- Subtree: {file: new.yaml}"), 1)
    robot.scheduler.run(until_s=1.5)
    assert "cannot include 'new.yaml'" in str(reports[-1][1])  # refused: no such file yet
    edit(tmp_path / "new.yaml", 'root:\n  Say: {text: "Brand new"}\n', 2)
    robot.scheduler.run(until_s=3.5)
    assert reports[-1] == ("greeter", None)
    assert said(robot)[-1] == "Brand new"


def test_each_reload_and_each_refused_edit_is_told_on_the_session_stream(tmp_path):
    robot, tree_file, _ = start(tmp_path)
    heard = EventCollector()
    robot.session.subscribe(heard, ("reload",))
    reloader = TreeReloader(robot.behaviors.loader, robot.trees, robot.clock, session=robot.session)
    robot.scheduler.add_hook(reloader)
    robot.scheduler.run(until_s=0.05, halt_at_end=False)
    edit(tree_file, GREETER.replace("PHRASE", "Good morning"), 1)
    robot.scheduler.run(until_s=1.05, halt_at_end=False)
    edit(tree_file, GREETER.replace("Check:", "Chek:"), 2)
    robot.scheduler.run(until_s=2.05, halt_at_end=False)
    reloads = heard.of(TreeReloaded)
    assert [(r.tree, r.problem == "") for r in reloads] == [("greeter", True), ("greeter", False)]
    assert "unknown node type 'Chek'" in reloads[1].problem


def test_a_save_that_finishes_while_the_file_is_read_is_loaded_too(tmp_path):
    robot, tree_file, reports = start(tmp_path)
    robot.scheduler.run(until_s=0.05)
    loader = robot.behaviors.loader
    read = loader.load_watching

    def read_during_a_save(path):
        loaded = read(path)  # the first half of a two-part save was read...
        if read_during_a_save.saving:
            read_during_a_save.saving = False
            edit(tree_file, GREETER.replace("PHRASE", "Good morning"), 2)  # ...then it ended
        return loaded

    read_during_a_save.saving = True
    loader.load_watching = read_during_a_save
    edit(tree_file, GREETER.replace("PHRASE", "Good morning").replace("root:", "ro"), 1)
    robot.scheduler.run(until_s=1.05)
    assert said(robot)[-1] == "Good morning"
    assert reports == [("greeter", None)]  # the half-saved file was never reported


ANSWERER = """\
    name: answerer
    rate_hz: 10
    root:
      Sequence:
        - OnEvent: {key: /speech/heard}
        - Say: {text: "I heard you"}
        - Wait: {seconds: 2.0}
    """


def ticking_until(robot, tree, until_s):
    """The robot's steps up to ``until_s``, the tree never stopped between (``run`` stops
    the trees when it ends)."""
    while tree.next_deadline_s <= until_s:
        robot.clock.sleep_until(tree.next_deadline_s)
        robot.scheduler.step()


def answering_robot(tmp_path):
    """A robot whose one tree answers each word, then waits 2 s; and its blackboard."""
    (tmp_path / "answerer.yaml").write_text(textwrap.dedent(ANSWERER))
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    services = simulated_services(clock)
    robot = Robot(load_behaviors([tmp_path]), clock=clock, services=services, blackboard=board)
    return robot, board


def test_a_word_that_came_while_the_old_version_was_busy_is_answered_by_the_new(tmp_path):
    robot, board = answering_robot(tmp_path)
    [tree] = robot.trees
    board.stage_event("/speech/heard", "hello")
    ticking_until(robot, tree, 0.3)  # it answered, and waits 2 s...
    board.stage_event("/speech/heard", "and again")  # ...when the child speaks again
    ticking_until(robot, tree, 0.5)
    tree.swap(tree.definition, tree.definition.build(tree.context), keep_events=True)
    ticking_until(robot, tree, 1.0)
    assert said(robot) == ["I heard you", "I heard you"]  # the new version answers it


def test_behaviors_built_afresh_answer_nothing_from_before(tmp_path):
    # the buttons' resume: what happened while paused is not answered late
    robot, board = answering_robot(tmp_path)
    board.stage_event("/speech/heard", "hello")
    board.commit()
    [tree] = robot.trees
    tree.replace(tree.definition)
    robot.scheduler.run(until_s=2.0)
    assert said(robot) == []

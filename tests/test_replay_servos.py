"""A replay whose file's servos cannot track the path (a small arm's weak, force-limited
servos) runs again with the scene's own servos, with gravity compensation, and says so."""

import pytest

import menagerie_like as ml
from armtransfer.ik.replay import MAX_SLOWDOWN, ReplayError, replay
from armtransfer.tasks.arms import arm_robot
from armtransfer.worlds.layout import ROOMS

SMALL_UR_MOUNT = dict(base_pos=(0.2, 0.0, 0.0), base_yaw=-1.835)
"""A mount of the small arm beside the room it stands in (one the automatic mount found)."""


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    path = ml.ALL["small_ur"](tmp_path_factory.mktemp("small"))
    tip = ml.SUGGESTED["small_ur"]
    return arm_robot(None, "cartesian", xml_path=path, **tip, **SMALL_UR_MOUNT)


def _states(robot):
    path = robot.shortest_path(robot.start_state(ROOMS.free_cell(0, 0)), ROOMS.free_cell(4, 5))
    assert path is not None
    return [s for s, _ in path]


def test_weak_file_servos_give_way_to_the_scenes_own(small):
    states = _states(small)
    own = replay(small, states, segment_seconds=0.06, settle_seconds=0.2)
    assert own.settings["servos"] == "scene"
    assert own.reached_goal and own.max_tracking_error_cells < 0.5, own.report()
    file_servos = own.report()["file_servos"]
    assert file_servos["max_tracking_error_cells"] > 0.5 or not file_servos["reached_goal"]
    # the file's servos alone, as asked for, are what the report said of them
    theirs = replay(small, states, segment_seconds=0.06, settle_seconds=0.2, servos="file")
    assert theirs.settings["servos"] == "file"
    assert round(theirs.max_tracking_error_cells, 4) == file_servos["max_tracking_error_cells"]
    assert theirs.reached_goal == file_servos["reached_goal"]


def test_servos_must_be_named(small):
    with pytest.raises(ReplayError, match="auto, file, scene"):
        replay(small, _states(small), servos="strong")


def test_saturated_file_servos_run_the_segment_slower_and_reach_the_goal(small):
    """At 0.06 s a segment the file's wrist servo is at its force limit and the tip misses;
    the replay runs the missed segment again at twice the time until the waypoint is met
    (at most ``MAX_SLOWDOWN`` times), and says how slow it went."""
    states = _states(small)
    hurried = replay(small, states, segment_seconds=0.06, settle_seconds=0.2, servos="file", max_slowdown=1)
    assert not hurried.reached_goal and "force limit" in hurried.shortfall()
    assert hurried.settings["slowdown"] == 1 and hurried.settings["slowed_segments"] == 0
    slowed = replay(small, states, segment_seconds=0.06, settle_seconds=0.2, servos="file")
    report = slowed.report()
    assert slowed.reached_goal, report
    assert 1 < report["slowdown"] <= MAX_SLOWDOWN == report["max_slowdown"] and report["slowed_segments"] >= 1
    assert slowed.duration > hurried.duration
    with pytest.raises(ReplayError, match="max_slowdown"):
        replay(small, states, max_slowdown=0)

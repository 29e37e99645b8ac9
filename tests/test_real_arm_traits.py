"""With only the file and the tool point it offers, arms with the traits of real arm files
compile, solve Table I where their cells allow, take a transfer from ``planar2:joint``, and
replay both paths to the goal; the mount search stays within 30 CPU seconds from an empty
cache: a 7-joint arm with a TCP its fingers reach past, a 6-joint arm with finger slides, a
small 6-joint arm with weak servos, a 5-joint arm with a jaw, a planar arm with a round pen,
a 7-joint arm with position servos of its own and no classes, a 6-joint arm with torque motors only.
"""

import time

import pytest

import armtransfer
import menagerie_like as ml
from armtransfer.errors import InvalidCellError
from armtransfer.ik.replay import replay
from armtransfer.tasks.arms import arm_robot, robot, tasks_solvable
from armtransfer.tasks.catalog import TABLE_I

LEAST_REACH = {"panda_tcp": 0.8, "ur5e_gripper": 0.8, "so100": 0.8,
               "small_ur": 0.6, "planar5_pen": 0.6,  # under 0.5 m of reach: 60%
               "iiwa": 0.8, "ur5e_motors": 0.8}
MOUNT_CPU_SECONDS = 30.0


def _tasks_allowed(r) -> int:
    """Table I tasks whose start and goal cells the robot reaches."""
    allowed = 0
    for task in TABLE_I.values():
        try:
            s, g = task.cells(r.layout)
            r.start_state(s)
            r.start_state(g, what="goal")
        except InvalidCellError:
            continue
        allowed += 1
    return allowed


@pytest.mark.slow
@pytest.mark.parametrize("name", list(LEAST_REACH))
def test_a_real_arm_file_works_as_it_is(tmp_path, monkeypatch, name):
    monkeypatch.setenv("ARMTRANSFER_CACHE", str(tmp_path / "cache"))  # an empty cache
    path = ml.ALL[name](tmp_path)
    tip = {k: v for k, v in ml.SUGGESTED[name].items() if k.startswith("tip")}  # no mount
    start = time.process_time()
    arm = arm_robot(None, "cartesian", xml_path=path, **tip)
    assert time.process_time() - start <= MOUNT_CPU_SECONDS
    assert arm.arm.mount_source == "automatic"
    assert arm.arm.reach >= LEAST_REACH[name]
    allowed = _tasks_allowed(arm)
    assert allowed >= 3 and tasks_solvable(arm) == allowed

    source = robot("planar2:joint")
    task = next(t for t, spec in TABLE_I.items() if tasks_solvable(arm, [spec]))
    result = armtransfer.transfer(source=source, target=arm, task=task, methods=["pseudo"], trials=1, seed=0,
                                  max_episodes=60, trajectory="optimal", controls=False)
    assert result.target.name == arm.name
    for r in (source, arm):
        s, g = TABLE_I[task].cells(r.layout)
        states = [st for st, _ in r.shortest_path(r.start_state(s), g)]
        rp = replay(r, states)
        assert rp.reached_goal and rp.max_deviation_cells < 1.0, (r.name, rp.report())

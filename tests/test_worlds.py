"""Worlds as data: layout files, the built-in and generated worlds, and --world / world= everywhere."""

import json

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import armtransfer
from armtransfer.cli import main
from armtransfer.errors import InvalidTaskError, InvalidWorldError
from armtransfer.tasks.catalog import TABLE_I, world_task, world_tasks
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.worlds.check import distance
from armtransfer.worlds.files import layout_data, load_layout
from armtransfer.worlds.generate import SIDES, generated_world
from armtransfer.worlds.grid import grid_rows, layout_from_rows
from armtransfer.worlds.layout import ROOMS, Layout
from armtransfer.worlds.resolve import WORLDS, layout_of_data, world

SMALL = """\
name = "corridor"
grid = \"\"\"
.......
.......
.......
###D###
.......
.......
.......
\"\"\"

[tasks]
down = { start = [0, 2], goal = [0, -2] }
across = { start = [-2, 2], goal = [2, -2] }
"""


def write(tmp_path, text, name="w.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def solved_by(robot, layout, name):
    start, goal = world_task(layout, name).cells()
    return robot.shortest_path(robot.start_state(start), goal)


def test_rooms_is_the_papers_layout_with_table_i_as_its_tasks():
    assert world() is ROOMS and world("rooms") is ROOMS
    assert [(t.start, t.goal) for t in world_tasks(ROOMS)] == [(t.start, t.goal) for t in TABLE_I.values()]
    assert world_task(ROOMS, "3") is TABLE_I[3] and world_task(ROOMS) is TABLE_I[1]


def test_the_papers_rooms_written_as_a_character_grid_is_the_same_world():
    rows = ROOMS.ascii({d: "D" for d in ROOMS.doors}).splitlines()
    again = layout_from_rows(grid_rows("\n".join(rows), "rooms"), "rooms", ROOMS.tasks)
    assert (again.lo, again.hi) == (ROOMS.lo, ROOMS.hi)
    assert np.array_equal(again.wall_mask, ROOMS.wall_mask)
    assert sorted(again.doors) == sorted(ROOMS.doors)


@pytest.mark.parametrize("name, side", [("rooms11", 11), ("rooms15", 15)])
def test_small_rooms_worlds_ship_with_tasks_both_grid_robots_solve(name, side):
    layout = world(name)
    assert layout.width == side and layout.name == name and len(layout.doors) == 4 and len(layout.tasks) == 3
    fine, coarse = grid_robot("fine", layout), grid_robot("coarse", layout)
    for task, start, goal in layout.tasks:
        path = solved_by(fine, layout, task)
        assert path is not None and len(path) - 1 == distance(layout, start, goal)
        assert solved_by(coarse, layout, task) is not None
    # four rooms in a ring: every free cell is reachable, and closing any one door keeps it so
    assert fine.reachable_from(fine.start_state(layout.cell(0, 0))).all()
    for door in layout.doors:
        closed = Layout(layout.lo, layout.hi, layout.walls, tuple(d for d in layout.doors if d != door))
        one_shut = grid_robot("fine", closed)
        assert one_shut.reachable_from(one_shut.start_state(layout.cell(0, 0))).all()


def test_generated_worlds_are_drawn_from_their_seed_and_every_task_is_solvable():
    assert generated_world(3) == generated_world(3)
    drawn = {tuple(layout_data(generated_world(seed))["grid"]) for seed in range(8)}
    assert len(drawn) > 1  # the seed changes the layout
    for side in (SIDES[0], SIDES[1], SIDES[-1]):
        for seed in range(3):
            layout = world(f"generated:{seed}:{side}")
            assert layout.width == side and len(layout.doors) == 4
            coarse = grid_robot("coarse", layout)
            for task, _, _ in layout.tasks:
                assert solved_by(coarse, layout, task) is not None


def test_a_layout_file_is_a_world(tmp_path):
    layout = load_layout(write(tmp_path, SMALL))
    assert layout.name == "corridor" and layout.width == 7 and layout.doors == ((0, 0),)
    assert [t[0] for t in layout.tasks] == ["down", "across"]
    assert distance(layout, (0, 2), (0, -2)) == 4
    assert layout_of_data(layout_data(layout), "here") == layout
    data = {"grid": [row for row in SMALL.split('"""')[1].split()], "tasks": {"1": {"start": [0, 2], "goal": [0, -2]}}}
    as_json = load_layout(write(tmp_path, json.dumps(data), "w.json"))
    assert np.array_equal(as_json.wall_mask, layout.wall_mask) and as_json.name == "w"


BAD = [
    (SMALL.replace(".......\n###D###", "......\n###D###"), "the grid is ragged: row 3 has 6 cells, row 1 has 7"),
    (SMALL.replace("###D###", "###X###"), "unknown character 'X' in grid row 4"),
    (SMALL.replace(".......\n.......\n.......\n###", ".......\n.......\n###", 1), "the grid must be square: 6 rows of 7 cells"),
    (SMALL.replace("###D###", "#######"), "task 'down': no path of free cells from its start (0, 2) to its goal (0, -2)"),
    (SMALL.replace("start = [0, 2]", "start = [0, 0]").replace("###D###", "#######"), "its start (0,0) is in a wall"),
    (SMALL.replace("goal = [2, -2]", "goal = [9, -2]"), "task 'across': its goal (9,-2) is off the grid"),
    (SMALL.replace("goal = [0, -2]", "goal = [0, 2]"), "its start and goal are the same cell"),
    (SMALL.replace("[tasks]", "[tasks]\nx = { start = [0, 2] }"), "task 'x' must have exactly a start and a goal"),
    (SMALL.replace('name = "corridor"', 'size = 7'), "unknown key 'size'; valid keys: name, description, grid, tasks"),
    (SMALL.split("[tasks]")[0], "tasks must be a table of at least one task"),
    ("grid = 'no", "not valid TOML"),
    (SMALL.replace("across =", '"a\\nb" ='), "a task's name must be 1 to 40 printable characters"),
]


@pytest.mark.parametrize("text, message", BAD)
def test_a_bad_layout_is_refused_in_one_line_and_nothing_is_written(tmp_path, capsys, text, message):
    path = write(tmp_path, text)
    with pytest.raises(InvalidWorldError, match=None) as err:
        load_layout(path)
    assert message in str(err.value) and "\n" not in str(err.value)
    out = tmp_path / "out.json"
    assert main(["rooms", "--world", str(path), "--trials", "1", "--json", str(out)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0] and not out.exists()


def test_unknown_worlds_and_tasks_name_the_valid_ones(tmp_path, capsys):
    with pytest.raises(InvalidWorldError, match="valid worlds: " + ", ".join(WORLDS)):
        world("rooms12")
    with pytest.raises(InvalidWorldError, match="generated:SEED or generated:SEED:SIDE"):
        world("generated:x")
    with pytest.raises(InvalidWorldError, match="no such file"):
        world(str(tmp_path / "absent.toml"))
    with pytest.raises(InvalidTaskError, match="unknown task '7' in world rooms11; valid tasks: 1, 2, 3"):
        world_task(world("rooms11"), 7)
    assert main(["rooms", "--world", "rooms15", "--task", "4", "--trials", "1"]) == 2
    assert "valid tasks: 1, 2, 3" in capsys.readouterr().err
    assert main(["rooms", "--task", "9"]) == 2  # the rooms' message is as it was
    assert capsys.readouterr().err.strip().endswith("unknown task 9; valid tasks: 1, 2, 3, 4")


def test_rooms_command_runs_on_a_world_and_names_it_only_there(tmp_path, capsys):
    out = tmp_path / "small.json"
    assert main(["rooms", "--world", "rooms11", "--task", "2", "--trials", "2", "--method", "none", "pseudo",
                 "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["world"] == "rooms11" and data["task"]["start"] == [2, 2] and data["distance"] == 12
    assert data["trajectory"]["steps"][0]["cell"] == [2, 2]  # cells in the world's coordinates
    assert capsys.readouterr().out.startswith("world rooms11, task 2:")
    rooms = tmp_path / "rooms.json"
    assert main(["rooms", "--trials", "1", "--method", "none", "--json", str(rooms)]) == 0
    assert "world" not in json.loads(rooms.read_text())


def test_the_api_takes_a_world_file_and_its_task_names(tmp_path):
    r = armtransfer.transfer("coarse", "fine", world=write(tmp_path, SMALL), task="across", methods=["pseudo"],
                             trials=2, seed=1, controls=False)
    assert r.task.start == (-2, 2) and r.distance == 8 and r.target.layout.name == "corridor"
    same = armtransfer.transfer("coarse", "fine", world=str(tmp_path / "w.toml"), task="across",
                                methods=["pseudo"], trials=2, seed=1, controls=False)
    assert same.to_json() == r.to_json()


def test_a_robot_of_another_world_is_refused(tmp_path):
    with pytest.raises(InvalidWorldError, match="robot fine moves in the world rooms11, not in rooms"):
        armtransfer.transfer("coarse", grid_robot("fine", world("rooms11")), world="rooms", trials=1)
    r = armtransfer.transfer("coarse", grid_robot("fine", world("rooms11")), methods=["none"], trials=1,
                             controls=False)  # no world given: the robot's
    assert r.task.start == (0, 0) and r.task.goal == (-4, 4)


def test_arms_list_reports_the_tasks_of_the_world(capsys):
    assert main(["arms", "list", "--world", "rooms11", "--arm", "planar2", "--actions", "joint"]) == 0
    header, row = capsys.readouterr().out.splitlines()[:2]
    assert header.split()[-2:] == ["tasks", "cache"] and row.split()[-2] == "3/3"


def test_rooms_env_takes_a_world():
    env = gym.make("armtransfer/Rooms-v0", world="rooms15", task="3", robot="coarse")
    check_env(env.unwrapped, skip_render_check=True)
    obs, info = env.reset(seed=0)
    assert env.unwrapped.robot.layout.xy(info["label"]) == (6, 6)
    with pytest.raises(InvalidWorldError):
        gym.make("armtransfer/Rooms-v0", world="nowhere")


def test_arm_env_on_a_small_world_builds_its_table_and_its_own_cache_entry():
    from armtransfer.ik.replay import robot_scene
    from armtransfer.ik.workspace import TABLE_SIDE, wall_boxes
    from armtransfer.tasks.arms import arm_robot, tasks_solvable

    env = gym.make("armtransfer/ArmRooms-v0", arm="planar2", actions="joint", world="rooms11", task=2)
    check_env(env.unwrapped, skip_render_check=True)
    robot = env.unwrapped.robot
    layout = robot.layout
    assert layout.name == "rooms11" and robot.arm.cell_size * layout.width == pytest.approx(TABLE_SIDE)
    assert tasks_solvable(robot) == 3 and robot.arm.reach == 1.0
    scene = robot_scene(robot)
    assert scene.env_geoms.sum() == 1 + len(wall_boxes(layout, robot.arm.cell_size))
    assert robot.arm.key != arm_robot("planar2", "joint").arm.key
    assert robot.arm.key != arm_robot("planar2", "joint", layout=world("rooms15")).arm.key


def test_arm_env_takes_an_arm_file_on_a_world():
    from armtransfer.models import ARMS

    env = gym.make("armtransfer/ArmRooms-v0", xml_path=str(ARMS["planar2"].xml_path), actions="cartesian",
                   base_pos=(-0.03, 0.03, 0.0), arm_name="my_planar2", world="rooms11", task=3)
    robot = env.unwrapped.robot
    assert robot.layout.name == "rooms11" and robot.arm.kind == "custom"
    _, info = env.reset(seed=0)
    assert robot.layout.xy(info["label"]) == (4, 4)


def test_continuous_arm_env_takes_a_world():
    env = gym.make("armtransfer/ContinuousArmRooms-v0", arm="planar3", world="rooms11", task=2)
    _, info = env.reset(seed=0)
    assert env.unwrapped.arm.layout.name == "rooms11" and world("rooms11").xy(info["label"]) == (2, 2)


def test_dmc_environment_takes_a_world():
    from armtransfer import dmc

    env = dmc.load(arm="planar2", actions="joint", task=3, world="rooms11")
    timestep = env.reset()
    assert world("rooms11").xy(int(timestep.observation["cell"])) == (4, 4)


def test_a_sweeps_world_goes_into_its_runs_keys(tmp_path):
    from armtransfer.experiments import sweep as sweeps

    base = {"name": "w", "tasks": [1], "pairs": [["coarse", "fine"]], "methods": ["none"]}
    plain = sweeps.expand(sweeps.normalise({"sweep": base}))
    assert sweeps.expand(sweeps.normalise({"sweep": dict(base, world="rooms")})) == plain  # rooms: keys as before
    small = sweeps.expand(sweeps.normalise({"sweep": dict(base, world="rooms11")}))
    assert small[0].key() != plain[0].key() and small[0].world["name"] == "rooms11"
    assert small[0].start == (0, 0) and small[0].goal == (-4, 4)
    assert sweeps.sweep_world(small[0]) is world("rooms11")
    with pytest.raises(sweeps.SweepFileError, match="unknown task 5 in world rooms11; valid tasks: 1, 2, 3"):
        sweeps.normalise({"sweep": dict(base, world="rooms11", tasks=[5])})
    write(tmp_path, SMALL, "corridor.toml")
    sweep_file = write(tmp_path, '[sweep]\nworld = "corridor.toml"\ntasks = ["down"]\ntrials = 2\n', "s.toml")
    assert main(["sweep", str(sweep_file), "--out", str(tmp_path / "store"), "--workers", "1"]) == 0
    assert main(["summarize", str(tmp_path / "store")]) == 0


def test_matrix_runs_every_task_of_a_world(tmp_path, capsys):
    assert main(["matrix", "--world", "rooms11", "--robots", "coarse,fine", "--methods", "pseudo", "--trials", "1",
                 "--out", str(tmp_path / "m"), "--workers", "1"]) == 0
    assert "tasks 1, 2, 3" in capsys.readouterr().out
    assert main(["matrix", "--world", "rooms11", "--robots", "coarse,fine", "--tasks", "4",
                 "--out", str(tmp_path / "n")]) == 2
    assert "valid tasks: 1, 2, 3" in capsys.readouterr().err and not (tmp_path / "n").exists()


@pytest.mark.parametrize("argv", [["reproduce", "--trials", "1"], ["benchmark", "--suite", "fast"]])
def test_commands_set_in_the_papers_rooms_refuse_other_worlds(tmp_path, capsys, argv):
    assert main([*argv, "--world", "rooms11", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "does not apply to" in err and "valid worlds: rooms" in err
    assert not (tmp_path / "out").exists()

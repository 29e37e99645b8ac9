"""Nothing a user gives is silently taken for something else: empty values, options of
another mode, unused or shadowing sweep tables, trajectories that are not paths of their
source, and MuJoCo's own detail of a broken arm file."""

import json

import pytest

from contract import SWEEP_WITH_ARM, refused
from armtransfer.errors import InvalidTrajectoryError
from armtransfer.learning import trajectory as trajectories
from armtransfer.tasks.catalog import table_task
from armtransfer.tasks.grid_robots import grid_robot


@pytest.mark.parametrize("argv,flag", [
    (["rooms", "--json", ""], "--json"),
    (["rooms", "--json", "  "], "--json"),
    (["arms", "--fast", "--out", ""], "--out"),
    (["arms", "--fast", "--out", "o", "--render", ""], "--render"),
    (["rooms", "--mapping", "", "--method", "mapping"], "--mapping"),
    (["rooms", "--trajectory", "optimal", "--trajectory", ""], "--trajectory"),
    (["matrix", "--robots", "coarse,fine", "--out", ""], "--out"),
    (["sweep", "s.toml", "--out", "st", "--address", ""], "--address"),
])
def test_an_empty_value_is_an_error_not_a_default(argv, flag, tmp_path, monkeypatch, capsys):
    err = refused(argv, tmp_path, monkeypatch, capsys)
    assert f"{flag} must not be empty" in err


@pytest.mark.parametrize("argv,flag", [
    (["arms", "list", "--arm", "planar2", "--json", "x.json"], "--json"),
    (["arms", "list", "--arm", "planar2", "--method", "bogus"], "--method"),
    (["arms", "list", "--arm", "planar2", "--out", "d"], "--out"),
    (["arms", "generate", "--family", "planar", "--dof", "2", "--out", "g", "--trials", "3"], "--trials"),
    (["arms", "generate", "--family", "planar", "--dof", "2", "--out", "g", "--arm", "planar2"], "--arm"),
    (["arms", "--fast", "--out", "o", "--family", "planar"], "--family"),
    (["arms", "--fast", "--out", "o", "--actions", "joint"], "--actions"),
])
def test_an_option_of_another_mode_is_refused(argv, flag, tmp_path, monkeypatch, capsys):
    err = refused(argv, tmp_path, monkeypatch, capsys)
    assert f"{flag} does not apply" in err and "its options:" in err


@pytest.mark.parametrize("argv,flag,users", [
    (["rooms", "--beta", "2"], "--beta", "dense"),
    (["rooms", "--method", "pseudo", "--max-span", "3"], "--max-span", "mapping"),
    (["rooms", "--method", "none", "--K", "0.1"], "--K", "pseudo"),
    (["rooms", "--method", "none", "--trajectory", "optimal"], "--trajectory", "pseudo"),
    (["arms", "--fast", "--out", "o", "--method", "none", "pseudo", "--beta", "2"], "--beta", "dense"),
    (["matrix", "--robots", "coarse,fine", "--methods", "none", "--trajectory", "optimal", "--out", "m"],
     "--trajectory", "pseudo"),
])
def test_a_method_option_no_chosen_method_uses_is_refused(argv, flag, users, tmp_path, monkeypatch, capsys):
    err = refused(argv, tmp_path, monkeypatch, capsys)
    assert f"{flag} does not apply to --method" in err and users in err.split("goes with the methods")[1]


@pytest.mark.parametrize("argv,flag", [
    (["bench", "--baseline-repeats", "0", "--baseline-steps", "10"], "--baseline-steps"),
    (["sweep", "s.toml", "--out", "st", "--executor", "ray", "--address", "127.0.0.1:1", "--workers", "2"],
     "--workers"),
    (["arms", "--fast", "--out", "o", "--trials", "5"], "--trials 5"),
    (["arms", "--fast", "--out", "o", "--patience", "50"], "--patience 50"),
])
def test_an_option_of_another_setting_is_refused(argv, flag, tmp_path, monkeypatch, capsys):
    assert f"{flag} does not apply" in refused(argv, tmp_path, monkeypatch, capsys)


@pytest.mark.parametrize("name,extra_pair,message", [
    ("fine", ', ["fine", "coarse"]', "has the name of a robot"),
    ("planar2", ', ["planar2:joint", "fine"]', "has the name of a robot"),
    ("myarm", "", "is not used by any pair"),
])
def test_every_sweep_arm_table_is_checked(name, extra_pair, message, tmp_path, monkeypatch, capsys, scara_xml):
    (tmp_path / "s.toml").write_text(SWEEP_WITH_ARM.format(name=name, extra_pair=extra_pair, xml=scara_xml))
    err = refused(["sweep", "s.toml", "--out", "store"], tmp_path, monkeypatch, capsys)
    assert f"arms.{name} {message}" in err


def _jumping_trajectory(tmp_path):
    """Task 1 for the coarse robot, but one step jumps across the grid."""
    start, goal = table_task(1).cells()
    traj = trajectories.shortest(grid_robot("coarse"), start, goal)
    cells = list(traj.cells)
    cells[3] = cells[-1]
    data = trajectories.Trajectory(tuple(cells), traj.actions, traj.goal, source="coarse").to_json()
    path = tmp_path / "jump.json"
    path.write_text(json.dumps(data))
    return path


def test_a_trajectory_that_jumps_is_refused_before_learning(tmp_path, monkeypatch, capsys):
    path = _jumping_trajectory(tmp_path)
    from armtransfer.experiments import engines

    def boom(*a, **k):
        raise AssertionError("learning started")

    monkeypatch.setattr(engines.Tabular, "trials", boom)
    err = refused(["rooms", "--method", "pseudo", "--trajectory", str(path), "--json", "o.json"], tmp_path,
                  monkeypatch, capsys)
    assert "step 3" in err and "not a path of coarse" in err
    with pytest.raises(InvalidTrajectoryError, match="not a path of coarse"):
        trajectories.check_source(trajectories.load(path), grid_robot("coarse"))


def test_a_trajectory_must_end_at_its_goal():
    start, goal = table_task(1).cells()
    traj = trajectories.shortest(grid_robot("coarse"), start, goal)
    short = trajectories.Trajectory(traj.cells[:-1], traj.actions[:-1], traj.goal, source="coarse")
    with pytest.raises(InvalidTrajectoryError, match="not to its goal"):
        trajectories.check_source(short, grid_robot("coarse"))
    assert len(trajectories.states_along(grid_robot("coarse"), traj)) == len(traj) + 1


def test_mujoco_xml_errors_keep_their_detail_and_leave_no_log(tmp_path, monkeypatch, capsys):
    (tmp_path / "broken.xml").write_text("<mujoco>\n<worldbody>\n<body>\n</worldbody>")
    err = refused(["arms", "list", "--arm", "planar2", "--arm-xml", "broken.xml"], tmp_path, monkeypatch, capsys)
    assert "Line number=3" in err
    (tmp_path / "nan.xml").write_text('<mujoco><worldbody><body name="a"><joint type="hinge" range="nan 1"/>'
                                      '<geom size="0.1"/><site name="tip"/></body></worldbody></mujoco>')
    err = refused(["arms", "list", "--arm", "planar2", "--arm-xml", "nan.xml"], tmp_path, monkeypatch, capsys)
    assert "not finite" in err and "NaN" in err
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def test_a_ray_address_without_ray_is_refused(tmp_path, monkeypatch, capsys):
    (tmp_path / "s.toml").write_text('[sweep]\ntasks = [1]\nmethods = ["none"]\ntrials = 1\n')
    err = refused(["sweep", "s.toml", "--out", "store", "--address", "127.0.0.1:6379"], tmp_path, monkeypatch,
                  capsys)
    assert "--address goes with --executor ray" in err


def test_no_cache_is_honoured_by_a_built_in_arm_spec():
    from armtransfer.tasks.specs import resolve

    assert resolve("planar2:joint", cache=False).arm.cache == "off"

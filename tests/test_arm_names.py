"""An arm file's robot goes by the name ``arms list`` prints (``NAME:ACTIONS``, NAME its
--arm-name or else its MJCF model attribute) in ``arms``, the API, sweeps and the matrix, with
the same file options; ``custom`` keeps working, and an unknown name lists the valid ones."""

import json

import pytest

import armtransfer
from armtransfer.cli import main
from armtransfer.errors import UnknownArmError, UnknownRobotError
from armtransfer.tasks.specs import resolve

FILE_FLAGS = ["--tip-site", "pen_tip", "--base-pos=-0.1,0,0"]
FILE_OPTIONS = dict(tip_site="pen_tip", base_pos=(-0.1, 0.0, 0.0))


def listed_name(capsys, xml, *extra) -> str:
    """The robot name ``arms list --arm-xml`` prints for the file."""
    assert main(["arms", "list", "--arm", "planar2", "--actions", "joint", "--arm-xml", str(xml),
                 *FILE_FLAGS, *extra]) == 0
    table = capsys.readouterr().out.partition("\n\n")[0]
    names = [line.split()[0] for line in table.splitlines()[1:]]
    return next(n for n in names if not n.startswith("planar2:"))


@pytest.mark.parametrize("extra", [[], ["--arm-name", "pen"]])
def test_arms_takes_the_name_arms_list_prints(tmp_path, scara_xml, capsys, extra):
    name = listed_name(capsys, scara_xml, *extra)
    assert name == ("pen:joint" if extra else "my_scara:joint")
    out = tmp_path / "run"
    code = main(["arms", "--fast", "--no-video", "--out", str(out), "--source", "planar2:joint",
                 "--target", name, "--arm-xml", str(scara_xml), *FILE_FLAGS, *extra, "--source-planner", "bfs",
                 "--task", "2", "--method", "none", "--trials", "1"])
    assert code == 0, capsys.readouterr().err
    assert json.loads((out / "results.json").read_text())["target"] == name


def test_an_unknown_name_lists_the_file_arms_name_too(tmp_path, scara_xml, capsys):
    for target, listing in (("scara:joint", "valid arms: planar2, planar3, planar4, ur5e_like, panda_like, "
                                                 "custom or my_scara (the arm of --arm-xml)"),
                            ("scara", "custom[:ACTIONS] or my_scara[:ACTIONS] (the arm of --arm-xml)")):
        assert main(["arms", "--fast", "--no-video", "--out", str(tmp_path / "x"), "--target", target,
                     "--arm-xml", str(scara_xml), *FILE_FLAGS]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and listing in err and "unknown" in err
    assert not (tmp_path / "x").exists()


def test_the_api_takes_the_files_name_and_custom(scara_xml):
    for target in ("my_scara:joint", "custom:joint"):
        r = armtransfer.transfer(source="planar2:joint", target=target, task=2, methods=["none"], trials=1,
                                 trajectory="optimal", controls=False, arm_xml=scara_xml, arm_options=FILE_OPTIONS)
        assert r.target.name == "my_scara:joint"
    named = resolve("pen:joint", xml_path=scara_xml, arm_name="pen", **FILE_OPTIONS)
    assert named.name == "pen:joint" and named.arm.xml_path == str(scara_xml)
    with pytest.raises(UnknownArmError, match="custom or pen") as err:  # --arm-name renames it
        resolve("my_scara:joint", xml_path=scara_xml, arm_name="pen", **FILE_OPTIONS)
    assert "\n" not in str(err.value)
    with pytest.raises(UnknownRobotError, match="or custom with --arm-xml"):  # without the file, no such arm
        resolve("my_scara:joint")


def test_a_built_in_arm_keeps_its_name(tmp_path):
    clash = tmp_path / "clash.xml"
    clash.write_text('<mujoco model="planar2"><worldbody/></mujoco>')
    robot = resolve("planar2:joint", xml_path=clash)
    assert robot.arm.kind == "planar"  # the built-in, not the file (which is not even an arm)


def test_a_sweep_names_its_arm_as_arms_list_does(tmp_path, scara_xml, capsys):
    from armtransfer.commands.sweep import check_runs
    from armtransfer.experiments import sweep as sweeps

    name = listed_name(capsys, scara_xml)
    raw = {"arms": {name.partition(":")[0]: {"xml": scara_xml.name, "tip_site": "pen_tip", "base_pos": [-0.1, 0, 0]}},
           "sweep": {"name": "s", "tasks": [2], "pairs": [["planar2:joint", name]], "methods": ["none"],
                     "trials": 1}}
    robots = check_runs(sweeps.expand(sweeps.normalise(raw, base=scara_xml.parent)))
    assert robots[name].name == name


def test_the_matrix_takes_the_file_as_custom_or_by_its_name(tmp_path, scara_xml):
    import argparse

    from armtransfer.commands import matrix as command
    from armtransfer.commands.sweep import check_runs
    from armtransfer.experiments import matrix

    parser = argparse.ArgumentParser()
    command.add_arguments(parser)
    for given in ("custom:joint", "my_scara:joint"):
        args = parser.parse_args(["--robots", f"planar2:joint,{given}", "--out", str(tmp_path / "m"),
                                  "--arm-xml", str(scara_xml), *FILE_FLAGS])
        robots, arms = command.arm_file_robots(args)
        assert robots == ["planar2:joint", "my_scara:joint"]
        assert arms == {"my_scara": {"xml": str(scara_xml.resolve()), "tip_site": "pen_tip",
                                     "base_pos": [-0.1, 0.0, 0.0]}}
        sweep = matrix.matrix_sweep(robots, [2], ["pseudo"], 1, arms=arms)
        built = check_runs(list(sweep.runs))
        assert built["my_scara:joint"].name == "my_scara:joint"
        assert built["my_scara:joint"].arm.mount == (-0.1, 0.0, 0.0)


@pytest.mark.parametrize("argv,message", [
    (["--robots", "planar2:joint,coarse", "--arm-xml", "{xml}"], "no robot of --robots names it (custom:ACTIONS "
                                                                      "or my_scara:ACTIONS)"),
    (["--robots", "planar2:joint,coarse", "--tip-site", "pen"], "--tip-site goes with --arm-xml"),
    (["--robots", "planar2:joint,custom:joint", "--arm-xml", "{xml}", "--arm-name", "coarse"],
     "--arm-name 'coarse' is the name of a built-in robot"),
    (["--robots", "planar2:joint,custom:joint,my_scara:joint", "--arm-xml", "{xml}"],
     "lists each robot once"),
    (["--robots", "planar2:joint,custom:joint"], "robot 'custom' needs --arm-xml"),
])
def test_bad_matrix_arm_input_is_one_line(tmp_path, scara_xml, capsys, argv, message):
    argv = [a.replace("{xml}", str(scara_xml)) for a in argv]
    assert main(["matrix", *argv, "--tasks", "2", "--trials", "1", "--out", str(tmp_path / "m")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err, err
    assert not (tmp_path / "m").exists()


@pytest.mark.slow
def test_a_matrix_runs_with_an_arm_file(tmp_path, scara_xml):
    out = tmp_path / "m"
    assert main(["matrix", "--robots", "planar2:joint,custom:joint", "--tasks", "2", "--methods", "pseudo",
                 "--trials", "1", "--trajectory", "optimal", "--arm-xml", str(scara_xml), *FILE_FLAGS, "--out",
                 str(out), "--workers", "1"]) == 0
    data = json.loads((out / "matrix.json").read_text())
    assert data["robots"] == ["planar2:joint", "my_scara:joint"]
    assert data["families"]["my_scara:joint"] == "custom" and data["runs"] == data["expected_runs"] == 8


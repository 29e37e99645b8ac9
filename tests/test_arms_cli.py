"""``armtransfer arms list``."""

import importlib.util

import pytest

from armtransfer import cli


@pytest.fixture(autouse=True)
def setup(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("ARMTRANSFER_CACHE", str(tmp_path_factory.getbasetemp() / "armcache"))
    # Only subcommands whose modules exist on this branch (others arrive with their issues).
    present = {k: v for k, v in cli.COMMANDS.items()
               if importlib.util.find_spec(f"armtransfer.commands.{v}") is not None}
    monkeypatch.setattr(cli, "COMMANDS", present)


def _one_line_error(capsys, argv, pattern):
    assert cli.main(argv) == 2
    out, err = capsys.readouterr()
    assert err.count("\n") == 1 and err.startswith("armtransfer arms: error:"), err
    assert "Traceback" not in err and pattern in err
    return err


def test_arms_list_reports_robots(capsys):
    assert cli.main(["arms", "list", "--arm", "planar2", "--actions", "joint,cartesian"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].split()[:5] == ["robot", "dof", "actions", "states", "reach"]
    rows = {line.split()[0]: line.split() for line in out[1:]}
    assert set(rows) == {"planar2:joint", "planar2:cartesian"}
    assert rows["planar2:joint"][1:3] == ["2", "4"]
    assert rows["planar2:cartesian"][5] == "4/4"


def test_bad_arm_xml_exits_2_with_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco><worldbody><body name='b'></worldbody></mujoco>")
    _one_line_error(capsys, ["arms", "list", "--arm-xml", str(bad), "--tip-site", "tip"],
                    "cannot load arm MJCF")
    _one_line_error(capsys, ["arms", "list", "--arm-xml", str(tmp_path / "nope.xml"),
                             "--tip-site", "tip"], "cannot read arm MJCF")


def test_byo_arm_errors_exit_2(tmp_path, capsys):
    xml = tmp_path / "slider.xml"
    xml.write_text("""<mujoco model="slider"><worldbody><body name="b">
      <joint name="j" type="slide" axis="1 0 0"/><geom name="g" size="0.01"/>
      <site name="tip"/></body></worldbody></mujoco>""")
    _one_line_error(capsys, ["arms", "list", "--arm-xml", str(xml), "--tip-site", "tip"],
                    "joint j on the chain from the base to the tool is a slide joint; only hinge joints")
    _one_line_error(capsys, ["arms", "list", "--arm-xml", str(xml), "--tip-site", "pen"],
                    "no site 'pen'; its sites: tip")


def test_unknown_arm_name_lists_valid_ones(capsys):
    _one_line_error(capsys, ["arms", "list", "--arm", "puma"], "valid arms: planar2")


def test_arms_list_includes_a_bring_your_own_arm(scara_xml, capsys):
    xml = scara_xml
    argv = ["arms", "list", "--arm", "planar2", "--actions", "joint", "--arm-xml", str(xml),
            "--tip-site", "pen_tip", "--base-pos=-0.1,0,0"]
    assert cli.main(argv) == 0
    table, _, notes = capsys.readouterr().out.partition("\n\n")
    rows = {line.split()[0]: line.split() for line in table.splitlines()[1:]}
    assert set(rows) == {"planar2:joint", "my_scara:joint"}
    assert "given mount --base-pos=-0.1,0,0" in notes and "joints shoulder-elbow" in notes
    assert rows["my_scara:joint"][1] == "2"


def test_arms_list_on_a_new_machine_prints_at_once_and_compiles_nothing(tmp_path):
    """An empty arm cache: every built-in robot listed, none compiled, within 10 s (a cold
    interpreter included); then a robot in the cache shows its figures."""
    import os
    import subprocess
    import sys
    import time

    from armtransfer.tasks.arms import robot_specs, spatial_joint_specs

    env = dict(os.environ, ARMTRANSFER_CACHE=str(tmp_path / "cache"))
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "armtransfer", "arms", "list"], env=env, capture_output=True,
                          text=True, timeout=60)
    seconds = time.perf_counter() - t0
    assert done.returncode == 0, done.stderr
    rows = {line.split()[0]: line.split() for line in done.stdout.splitlines()[1:] if line[:1].isalpha() and ":" in line.split()[0]}
    assert set(rows) == set(robot_specs() + spatial_joint_specs())
    assert all(r[3] == "-" and r[-1] == "none" for r in rows.values())
    assert "not compiled yet" in done.stdout and "--arm" in done.stdout
    assert not list((tmp_path / "cache").rglob("*.npz")), "the listing compiled a robot"
    assert seconds < 10, f"{seconds:.1f} s"
    subprocess.run([sys.executable, "-m", "armtransfer", "arms", "list", "--arm", "planar2", "--actions", "joint"],
                   env=env, capture_output=True, text=True, timeout=300, check=True)
    again = subprocess.run([sys.executable, "-m", "armtransfer", "arms", "list"], env=env, capture_output=True,
                           text=True, timeout=60, check=True).stdout
    row = next(line.split() for line in again.splitlines() if line.startswith("planar2:joint "))
    assert row[2] == "4" and row[-1] == "hit"

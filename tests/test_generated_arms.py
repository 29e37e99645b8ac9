"""Generated arms: same contract as the built-in ones, deterministic, rejected draws redrawn,
usable anywhere an arm file is."""

import numpy as np
import pytest

from armtransfer.cli import main
from armtransfer.errors import ArmTransferError
from armtransfer.ik import contract
from armtransfer.learning.config import LearnerConfig
from armtransfer.experiments.experiment import run_method
from armtransfer.models import ARMS, generate, mjcf
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.generated import generate_arm, read_sidecar
from armtransfer.worlds.layout import ROOMS
from armtransfer.tasks.specs import resolve


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    out = tmp_path_factory.mktemp("gen")
    return {fam: generate_arm(fam, dof, 11, out) for fam, dof in [("planar", 3), ("spatial6", 6), ("spatial7", 7)]}


@pytest.mark.parametrize("arm", list(ARMS))
def test_built_in_arms_are_written_by_the_same_mjcf_writers(arm):
    assert mjcf.BUILT_IN[arm]() == ARMS[arm].xml_path.read_text()


@pytest.mark.parametrize("arm", list(ARMS))
def test_built_in_arms_meet_the_contract(arm):
    info = ARMS[arm]
    assert contract.problems(info.xml_path, ROOMS, mount=info.mount_pos, yaw=info.mount_yaw) == []


def test_generated_arms_meet_the_contract_and_solve_table_i(generated):
    for fam, arm in generated.items():
        side = read_sidecar(arm.xml_path)
        assert side["family"] == fam and side["seed"] == 11
        assert contract.problems(arm.xml_path, ROOMS, mount=side["mount_pos"], yaw=side["mount_yaw"]) == []
        robot = resolve(f"{arm.xml_path}:cartesian")
        assert robot.name == f"{arm.name}:cartesian" and robot.arm.dof == arm.draw.dof
        for task in TABLE_I.values():
            s, g = task.cells()
            assert robot.shortest_path(robot.start_state(s), g) is not None
        assert (arm.xml_path.parent / "README.md").read_text().startswith(f"# {arm.name}")
        if arm.draw.tip_down:  # a spatial arm's home is solved with the tool over the table's centre
            assert robot.arm.reach > 0.8


def test_the_contract_names_what_is_wrong(tmp_path):
    xml = ARMS["planar2"].xml_path.read_text()
    broken = xml.replace('name="tip"', 'name="pen"').replace('<key name="home"', '<key name="rest"')
    broken = broken.replace('type="hinge" axis="0 0 1" range="-3 3"', 'type="slide" axis="0 0 1" range="-3 3"')
    path = tmp_path / "broken.xml"
    path.write_text(broken.replace('<position name="joint2"', '<motor name="joint2"').replace(
        'joint="joint2" ctrlrange', 'joint="joint2" ctrlrange'))
    found = contract.problems(path, ROOMS)
    assert "no site named 'tip'" in found
    assert "no keyframe named 'home'" in found
    assert "actuator joint2 is not a position servo" in found
    (tmp_path / "bad.xml").write_text("<mujoco><worldbody><body>")
    assert contract.problems(tmp_path / "bad.xml", ROOMS)[0].startswith("does not compile")


def test_same_seed_same_files_other_seed_other_arm(tmp_path, generated):
    # the module's arm again (same seed as the fixture: its compiled robot is the cache's already)
    a = generate_arm("planar", 3, 11, tmp_path / "a")
    b = generate_arm("planar", 3, 11, tmp_path / "b")
    for name in ("gen_planar3_s11.xml", "gen_planar3_s11.json", "README.md"):
        assert (a.xml_path.parent / name).read_bytes() == (b.xml_path.parent / name).read_bytes()
    assert a.xml_path.read_bytes() == generated["planar"].xml_path.read_bytes()
    # another seed draws another arm (its draws alone: compiling one is ten seconds of IK)
    rng11, rng12 = np.random.default_rng(11), np.random.default_rng(12)
    draws = [generate.draw_arm("planar", 3, rng11, "x").params for _ in range(a.draws)]
    assert draws[-1]["lengths"] == a.draw.params["lengths"]  # the generator's own draws, replayed
    assert generate.draw_arm("planar", 3, rng12, "x").params["lengths"] != draws[0]["lengths"]


def test_a_rejected_draw_is_redrawn_and_the_reasons_kept(tmp_path, monkeypatch, generated):
    calls = []
    real = generate.draw_arm

    def first_too_short(family, dof, rng, name):
        # the first draw cannot reach the far rooms; it leaves the generator's stream untouched, so
        # the next is the module fixture's arm (seed 11), whose compiled robot the cache has
        d = real(family, dof, np.random.default_rng(99) if not calls else rng, name)
        calls.append(d)
        if len(calls) == 1:
            lengths = [0.08, 0.06, 0.04]
            xml = mjcf.planar_arm(name, lengths, d.params["limits"], d.params["home"], height=0.12, drop=0.025)
            d = generate.ArmDraw(d.name, d.family, d.dof, xml, {**d.params, "lengths": lengths}, d.mount_pos,
                                 d.mount_yaw, d.tip_down, d.kind, d.joint_step)
        return d

    monkeypatch.setattr("armtransfer.tasks.generated.draw_arm", first_too_short)
    arm = generate_arm("planar", 3, 11, tmp_path)
    assert arm.draws >= 2 and len(arm.rejected) == arm.draws - 1 == len(calls) - 1
    assert arm.rejected[0].startswith("draw 1: the tip cannot get near Table I cell")
    assert read_sidecar(arm.xml_path)["rejected"] == arm.rejected
    assert arm.draws == generated["planar"].draws + 1
    assert arm.xml_path.read_bytes() == generated["planar"].xml_path.read_bytes()


def test_no_usable_draw_is_a_one_line_error_and_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.setattr(generate, "PLANAR_REACH", (0.05, 0.06))
    with pytest.raises(ArmTransferError) as err:
        generate_arm("planar", 2, 0, tmp_path / "none", max_draws=2)
    assert "no usable planar arm with 2 joints in 2 draws from seed 0" in str(err.value)
    assert "\n" not in str(err.value)
    assert not (tmp_path / "none").exists()


def test_a_generated_arm_learns_as_a_bring_your_own_arm(generated):
    robot = resolve(f"{generated['planar'].xml_path}:cartesian")
    s, g = TABLE_I[1].cells()
    res = run_method("none", robot, s, g, None, 1, 0, LearnerConfig(max_episodes=5))
    assert res.trials[0].exploration_steps is not None and res.trials[0].episodes == 5


@pytest.mark.parametrize("args,message", [
    (["--family", "octo", "--dof", "3"], "unknown arm family 'octo'; valid families: planar, spatial6, spatial7"),
    (["--family", "planar", "--dof", "9"], "valid joint counts: 2, 3, 4, 5, 6, 7"),
    (["--family", "spatial7", "--dof", "6"], "valid joint counts: 7"),
    (["--dof", "3"], "arms generate needs --family"),
])
def test_bad_generate_input_is_one_line_exit_2(tmp_path, capsys, args, message):
    out = tmp_path / "g"
    assert main(["arms", "generate", *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_arms_generate_writes_the_arm(tmp_path, capsys, generated):
    # the module fixture's arm: its compiled robot is in the run's arm cache already
    assert main(["arms", "generate", "--family", "planar", "--dof", "3", "--seed", "11", "--out", str(tmp_path)]) == 0
    assert "gen_planar3_s11.xml:cartesian" in capsys.readouterr().out
    assert np.isfinite(read_sidecar(tmp_path / "gen_planar3_s11" / "gen_planar3_s11.xml")["reach"])


def test_an_arm_file_keeps_its_generated_mount_everywhere(generated):
    """As xml_path (the API, ArmRooms-v0) and as a spec, a generated arm is mounted as generated."""
    import gymnasium as gym

    from armtransfer.tasks.arms import arm_robot

    arm = generated["spatial6"]
    side = read_sidecar(arm.xml_path)
    robot = arm_robot(None, "cartesian", xml_path=arm.xml_path)
    assert robot.arm.mount == tuple(side["mount_pos"]) and robot.arm.yaw == side["mount_yaw"]
    env = gym.make("armtransfer/ArmRooms-v0", xml_path=str(arm.xml_path), actions="cartesian", task=1)
    assert env.unwrapped.robot.arm.mount == robot.arm.mount
    assert env.unwrapped.robot.name == f"{arm.name}:cartesian"
    env.close()

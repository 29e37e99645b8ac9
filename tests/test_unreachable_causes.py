"""When no configuration or no mount works, the one-line error names the cause, measured on
the best try: the bodies in contact and with what, the joints at a limit, how far the tip
or the tool's lowest point stayed (``armtransfer.ik.diagnose``)."""

import re
import time

import pytest

import menagerie_like as ml
from armtransfer.errors import UnreachableTableError
from armtransfer.tasks.arms import arm_robot

LOW_LINK = """<mujoco model="lowlink"><compiler angle="radian"/><worldbody>
  <body name="link1" pos="0 0 0.05"><joint name="j1" axis="0 0 1" range="-3 3"/>
    <geom type="capsule" size="0.01" fromto="0 0 0 0.15 0 0"/>
    <body name="link2" pos="0.15 0 0"><joint name="j2" axis="0 0 1" range="-2.5 2.5"/>
      <geom type="capsule" size="0.008" fromto="0 0 -0.05 0.12 0 -0.05"/>
      <body name="stylus" pos="0.12 0 -0.046"><geom type="cylinder" size="0.0015 0.002" pos="0 0 0.002"/>
        <site name="tip"/></body>
    </body></body></worldbody>
  <actuator><position joint="j1" kp="10"/><position joint="j2" kp="10"/></actuator></mujoco>"""
"""A planar arm whose second link hangs 5 cm below its joint, lower than the stylus: it lies
in the table wherever the stylus rides 4 mm above it (the stylus, a body of its own, is the
tool; the link is not)."""


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    out = tmp_path_factory.mktemp("causes")
    (out / "lowlink.xml").write_text(LOW_LINK)
    ur5e = ml.ALL["ur5e"](out)
    stiff = ur5e.read_text().replace('<joint name="elbow_joint" class="ur5e/size3_limited"/>',
                                     '<joint name="elbow_joint" class="ur5e/size3_limited" range="-0.2 0.2"/>')
    (ur5e.parent / "ur5e_stiff.xml").write_text(stiff)
    return {"lowlink": out / "lowlink.xml", "ur5e": ur5e, "stiff": ur5e.parent / "ur5e_stiff.xml"}


def _error(**kwargs) -> str:
    with pytest.raises(UnreachableTableError) as err:
        arm_robot(None, "cartesian", cache=False, **kwargs)
    text = str(err.value)
    assert "\n" not in text
    return text


def test_a_link_in_the_table_is_named(files):
    text = _error(xml_path=files["lowlink"], tip_site="tip", base_pos=(0.0, 0.0, 0.0), base_yaw=0.0)
    assert "the arm touches: link2 with the table" in text


def test_a_joint_at_its_limit_is_named(files):
    """The elbow, held to +-0.2 rad, stops the tip short of the table, and the diagnosis names it.

    Which of its two limits the best try ends at is not forced by the geometry: it follows the
    last digits of the IK solve, which follow OpenBLAS's kernel for the processor (the lower
    limit with OPENBLAS_CORETYPE=SkylakeX, the upper one with Haswell or Prescott). The promise is
    that the joint is named, at a limit."""
    mount = {k: v for k, v in ml.SUGGESTED["ur5e"].items() if k != "base_pos"}
    text = _error(xml_path=files["stiff"], base_pos=(0.0, -0.42, 0.0), **mount)
    assert re.search(r"\belbow_joint at its (lower|upper) limit\b", text), text
    assert "the tip stays" in text
    others = re.findall(r"(\w+) at its (?:lower|upper) limit", text)
    assert set(others) <= {"elbow_joint"}, f"joints named at a limit that were not held: {others}"


def test_a_tool_held_too_high_says_how_high(files):
    mount = {k: v for k, v in ml.SUGGESTED["ur5e"].items() if k != "base_pos"}
    text = _error(xml_path=files["ur5e"], base_pos=(0.0, -0.42, 0.9), **mount)
    assert "the tool's lowest point is" in text and "mm above the tabletop" in text


@pytest.mark.slow
def test_a_failing_mount_search_names_the_cause_at_its_best_pose_within_30_s(files):
    start = time.perf_counter()
    text = _error(xml_path=files["lowlink"], tip_site="tip")
    assert time.perf_counter() - start < 30
    assert "from any base pose tried (at the best, base at" in text and "link2 with the table" in text
    assert "--tip-offset" not in text  # a planar arm's tool is not kept pointing down

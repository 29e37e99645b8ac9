"""A joint range written with its ends reversed (``range="3 -3"``): MuJoCo's automatic limits
take such a joint as unlimited without a word, so an arm file that says it is limited would be
compiled as one that is not. Refused in one line naming the joint, before anything is built."""

from __future__ import annotations

from pathlib import Path

from armtransfer.errors import ArmModelError


def check_joint_ranges(path: Path, where: str) -> None:
    """Raise a one-line :class:`ArmModelError` for the first joint of the arm file ``path`` whose
    range has its lower end above its upper. A file MuJoCo cannot compile is left to the
    loader, which says why."""
    import mujoco  # here: tasks import this module and load no MuJoCo

    try:
        model = mujoco.MjSpec.from_file(str(path)).compile()
    except Exception:  # noqa: BLE001 - the loader names the fault
        return
    for j in range(model.njnt):
        lo, hi = (float(v) for v in model.jnt_range[j])
        if lo > hi:
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"#{j}"
            raise ArmModelError(
                f"arm MJCF {where}: joint {name} has range=\"{lo:g} {hi:g}\", its lower end above its upper, which "
                f"MuJoCo would take as no limit; give range=\"{hi:g} {lo:g}\", or leave range out for an unlimited "
                "joint")

"""Continuous-state arms by name: ``continuous_arm("planar3")`` or an arm file.

The arm is built in the same MuJoCo scene as its discrete robots (``tasks.arms.arm_scene``:
the same mount, tool point, cell size and layout) and moved by the ``joint`` action model's
increments (the arm's lattice step: ``ARMS[arm].joint_step`` for a built-in arm, the
generator's for a generated arm file, else ``joint_step=`` or the finest step of
``ik.compile.STEP_LADDER`` whose lattice ``compile_joint`` would allow), with no lattice
laid out: ``ik.continuous.ContinuousArm``. A spatial arm (``ur5e_like``, ``panda_like``, a
6- or 7-joint file) is ``ik.continuous3d.SpatialContinuousArm``: three joints moved over the 3D
workspace, labelled with voxels, as its ``joint`` robot (``ik.voxels``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import armtransfer.checks as checks
from armtransfer.errors import ArmModelError, UnknownArmError
from armtransfer.models import ARMS
from armtransfer.tasks.arms import arm_scene, automatic_mount, make_tool, read_sidecar
from armtransfer.tasks.generated import generated_file
from armtransfer.worlds.layout import ROOMS, Layout

ACTIONS = ("joint",)
"""The action models a continuous arm has."""
ARM_KEYWORDS = ("tip_site", "tip_body", "tip_offset", "base_pos", "base_yaw", "joint_step", "cell_size", "noise")
""":func:`continuous_arm`'s keywords for the arm's tool point, mount and step (besides ``xml_path``)."""


def parse_spec(spec: str) -> tuple[str | None, str | None]:
    """'planar3', 'planar3:joint' -> ('planar3', None); 'PATH.xml[:joint]' -> (None, 'PATH.xml');
    'gen:planar:DOF:SEED[:joint]' -> (None, the generated arm's file, generated at its first use).
    Anything else is a one-line error listing the valid arms and action models."""
    if not isinstance(spec, str):
        raise UnknownArmError(f"a continuous arm is named by a string, got {spec!r}")
    if spec.startswith("gen:"):
        xml, _, _ = generated_file(spec)
        parts = spec.split(":")
        path, name, actions = str(xml), None, parts[4] if len(parts) > 4 else ""
    elif ".xml" in spec:
        path, _, actions = spec.rpartition(":") if not spec.endswith(".xml") else (spec, "", "")
        name = None
    else:
        name, _, actions = spec.partition(":")
        path = None
        if name not in ARMS:
            raise UnknownArmError(f"unknown continuous arm {name!r}; valid arms: {', '.join(ARMS)}, PATH.xml "
                                  "(an arm file) or gen:planar:DOF:SEED")
    if actions and actions not in ACTIONS:
        raise UnknownArmError(f"a continuous arm has no action model {actions!r}; valid action models: "
                              f"{', '.join(ACTIONS)}")
    return name, path


def continuous_arm(spec: str | None = None, *, xml_path=None, tip_site: str | None = None,
                   tip_body: str | None = None, tip_offset=None, base_pos=None, base_yaw: float | None = None,
                   joint_step: float | None = None, cell_size: float | None = None, layout: Layout = ROOMS,
                   noise: float = 0.0):
    """The continuous arm of a built-in arm (``spec``, e.g. ``"planar3:joint"``) or of an arm
    file (``spec`` ``"PATH.xml"`` or ``xml_path=``) with its tool point and mount
    (a generated arm's from its sidecar; without ``base_pos`` the automatic mount), on the
    world ``layout`` (its cell size ``ik.workspace.world_cell`` unless given); ``noise``: the
    actuation noise sigma (``ik.continuous``; 0, the default: none). A planar arm is an
    ``ik.continuous.ContinuousArm``; a spatial one an ``ik.continuous3d.SpatialContinuousArm``
    over the 3D workspace (the moved joints, origin and default step of its ``joint`` robot)."""
    from armtransfer.ik.continuous import MAX_NOISE, ContinuousArm  # MuJoCo, only when an arm is built
    from armtransfer.ik.continuous3d import SpatialContinuousArm  # MuJoCo, only when an arm is built
    name, path = parse_spec(spec) if spec is not None else (None, None)
    if xml_path is not None:
        path = str(checks.path(xml_path, "the arm file (xml_path)", error=ArmModelError))
    if joint_step is not None:
        joint_step = checks.real(joint_step, "the joint step (radians)", 0.0, np.pi, lo_open=True,
                                 error=ArmModelError)
    noise = checks.real(noise, "the actuation noise (noise, sigma)", 0.0, MAX_NOISE, error=ArmModelError)
    if path is None:
        if name is None:
            raise UnknownArmError("give a continuous arm: a built-in planar arm or an arm file")
        scene = arm_scene(name, cell_size=cell_size, layout=layout)
        if ARMS[name].kind != "planar":  # over the 3D workspace, its step chosen as its joint robot's
            return SpatialContinuousArm(scene, joint_step, noise)
        return ContinuousArm(scene, joint_step or ARMS[name].joint_step, noise)
    if tip_site is None and tip_body is None and spec is not None and spec.startswith("gen:"):
        tip_site = "tip"  # a generated arm's tool point
    generated = read_sidecar(path) if base_pos is None else None
    if generated is not None:
        base_pos, base_yaw = tuple(generated["mount_pos"]), float(generated["mount_yaw"])
        joint_step = joint_step or generated["joint_step"]
    if base_pos is None:
        tool = make_tool(tip_site, tip_body, tip_offset)
        pose = automatic_mount(Path(path), tool, cell_size=cell_size, layout=layout, yaw=base_yaw)
        base_pos, base_yaw = pose.pos, pose.yaw
    scene = arm_scene(None, cell_size=cell_size, xml_path=path, tip_site=tip_site, tip_body=tip_body,
                      tip_offset=tip_offset, base_pos=base_pos, base_yaw=base_yaw, layout=layout)
    if not scene.planar:
        return SpatialContinuousArm(scene, joint_step, noise)
    return ContinuousArm(scene, joint_step or ladder_step(scene), noise)


def ladder_step(scene) -> float:
    """The step ``ik.compile.compile_joint`` picks for the arm when none is given, about its home
    (unlimited joints: pi either side of it)."""
    from armtransfer.ik.compile import joint_box, ladder_step as pick  # MuJoCo, only when an arm is built

    home = scene.home.astype(float)
    return pick(*joint_box(scene, home), home)

"""Arm files written the way MuJoCo Menagerie writes its arms, for the bring-your-own-arm tests.

Each function writes one arm folder into ``directory`` (an MJCF file plus a mesh folder of
tiny generated meshes) and returns the MJCF path. The files have the traits real Menagerie
arms have and the project's own arms do not (issue 11):

- default class names containing ``/`` (``ur5e/visual``), which dm_control.mjcf rejects;
- ``<compiler meshdir=...>`` with mesh files in a folder next to the MJCF;
- ``general`` actuators with ``biastype="affine"``, named differently from their joints;
- a Panda-style gripper: two slide fingers whose type is set by a default class, coupled
  by a fixed tendon driven by one actuator, plus an equality constraint between them;
- a flange site (``attachment_site``), or no site at all;
- a ``home`` keyframe that includes the finger joints, or no keyframe;
- a 5-joint low-cost arm with a jaw, standing on a body far from the file's origin, and a
  planar 5-joint arm whose qpos0 is the straight, singular pose.

The geometry is the project's own: UR5e and Panda from their published DH parameters
(``armtransfer.models.mjcf``), the SO100-style arm with the SO-ARM100's joint layout and
proportions at 1.8 times its size. Masses are close to the real arms' (the SO100-style
one's scaled with its volume); inertias are those of solid cylinders along the links. Every
file compiles with ``mujoco.MjModel.from_xml_path`` alone. Gripper tips are narrow (a closed
gripper is under 1 cm wide over its last 2 cm) so that, with the tip 4 mm above the table,
it passes the rooms' 1-cell doors between 2 cm walls as the built-in arms' styluses do.

``SUGGESTED`` gives a tip and a mount per arm (a mount a user could give by hand).
Nothing here depends on pytest; ``python tests/menagerie_like.py
DIR`` writes all of the arms.
"""

from __future__ import annotations

import math
import struct
import sys
from pathlib import Path

import numpy as np

from armtransfer.models.mjcf import (PANDA_FLANGE, PANDA_LIMITS, UR5E_DH, panda_frames,
                                     ur5e_frames)

# --------------------------------------------------------------------------- formatting


def _f(v: float) -> str:
    s = f"{float(v):.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "", "-") else s


def _v(values) -> str:
    return " ".join(_f(x) for x in values)


def _quat_rx(angle: float) -> tuple[float, float, float, float]:
    return (math.cos(angle / 2), math.sin(angle / 2), 0.0, 0.0)


def _quat_rz(angle: float) -> tuple[float, float, float, float]:
    return (math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2))


# --------------------------------------------------------------------------- meshes


def box_mesh(p0, p1, half_width: float) -> tuple[np.ndarray, np.ndarray]:
    """A closed box of square section 2 * half_width around the segment p0 -> p1 (or a cube
    of side 2 * half_width at p0 when the segment is empty). Faces wind outwards."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    axis = p1 - p0
    length = float(np.linalg.norm(axis))
    if length < 1e-9:
        axis, length, p0 = np.array([0.0, 0.0, 1.0]), 2 * half_width, p0 - (0, 0, half_width)
    w = axis / length
    helper = np.array([1.0, 0.0, 0.0]) if abs(w[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(w, helper)
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    corners = []
    for k in (0.0, length):
        for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            corners.append(p0 + w * k + half_width * (a * u + b * v))
    verts = np.array(corners)
    # u x v = w, so counter-clockwise seen from +w is outwards at the far end.
    faces = np.array([
        [0, 2, 1], [0, 3, 2],  # near end (-w)
        [4, 5, 6], [4, 6, 7],  # far end (+w)
        [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
        [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7],
    ])
    return verts, faces


def prism_mesh(radius: float, half_height: float, sides: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """A closed regular prism about the z axis (a coarse cylinder), faces winding outwards."""
    ang = 2 * np.pi * np.arange(sides) / sides
    ring = np.column_stack([radius * np.cos(ang), radius * np.sin(ang)])
    verts = np.vstack([np.column_stack([ring, np.full(sides, -half_height)]),
                       np.column_stack([ring, np.full(sides, half_height)]),
                       [[0, 0, -half_height], [0, 0, half_height]]])
    lo_c, hi_c = 2 * sides, 2 * sides + 1
    faces = []
    for i in range(sides):
        j = (i + 1) % sides
        faces += [[i, j, sides + j], [i, sides + j, sides + i],  # side
                  [lo_c, j, i], [hi_c, sides + i, sides + j]]    # bottom, top
    return verts, np.array(faces)


def write_obj(path: Path, verts: np.ndarray, faces: np.ndarray) -> None:
    lines = [f"v {_v(p)}" for p in verts] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")


def write_stl(path: Path, verts: np.ndarray, faces: np.ndarray) -> None:
    """Binary STL: 80-byte header, triangle count, then normal + 3 vertices + 2 bytes each."""
    tri = verts[faces].astype(np.float32)
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    record = np.zeros(len(faces), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    record["n"], record["v"] = normals, tri
    path.write_bytes(b"armtransfer test mesh".ljust(80, b" ") + struct.pack("<I", len(faces))
                     + record.tobytes())


class _Meshes:
    """Collects the mesh files of one arm and the ``<mesh>`` asset lines naming them."""

    def __init__(self, folder: Path, fmt: str) -> None:
        self.folder, self.fmt, self.assets = folder, fmt, []
        folder.mkdir(parents=True, exist_ok=True)

    def add(self, name: str, verts, faces, *, named: bool = False, fmt: str | None = None) -> str:
        fmt = fmt or self.fmt
        (write_obj if fmt == "obj" else write_stl)(self.folder / f"{name}.{fmt}", verts, faces)
        # Menagerie often names meshes by their file stem only; the Panda-style ones name them.
        self.assets.append(f'    <mesh name="{name}" file="{name}.{fmt}"/>' if named
                           else f'    <mesh file="{name}.{fmt}"/>')
        return name


# --------------------------------------------------------------------------- inertia


def cylinder_inertial(mass: float, radius: float, p0, p1) -> str:
    """``<inertial>`` of a solid cylinder of ``radius`` from p0 to p1 (body frame); a
    cylinder as long as it is wide at p0 when p0 == p1."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    axis = p1 - p0
    length = float(np.linalg.norm(axis))
    if length < 1e-9:
        axis, length = np.array([0.0, 0.0, 1.0]), 2 * radius
        centre = p0
    else:
        centre = (p0 + p1) / 2
    w = axis / np.linalg.norm(axis)
    along = mass * radius ** 2 / 2
    across = mass * (3 * radius ** 2 + length ** 2) / 12
    inertia = across * np.eye(3) + (along - across) * np.outer(w, w)
    full = (inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2])
    return (f'<inertial pos="{_v(centre)}" mass="{_f(mass)}" '
            f'fullinertia="{" ".join(f"{x:.6g}" for x in full)}"/>')


def _shorten(p0, p1, clearance: float) -> np.ndarray:
    """p1 moved towards p0 by ``clearance`` (never past the middle): a link's bar stops short of
    the next joint's housing, so links two apart do not overlap where the joints are offset."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    length = float(np.linalg.norm(p1 - p0))
    if length < 1e-9:
        return p1
    return p1 - (p1 - p0) * min(0.5, clearance / length)


def _write(folder: Path, name: str, text: str) -> Path:
    path = folder / f"{name}.xml"
    path.write_text(text)
    return path


# --------------------------------------------------------------------------- UR5e style

UR5E_JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
               "wrist_2_joint", "wrist_3_joint")
UR5E_ACTUATORS = ("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3")
UR5E_BODIES = ("shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link",
               "wrist_3_link")
UR5E_MASSES = (3.7, 8.393, 2.275, 1.219, 1.219, 0.1889)  # the UR5e's published link masses (kg)
UR5E_RADII = (0.06, 0.055, 0.045, 0.04, 0.04, 0.035)
UR5E_PEDESTAL = 0.04  # the base's height below the shoulder column (m)
UR5E_HOME = (-1.5708, -1.5708, 1.5708, -1.5708, -1.5708, 0.0)
"""The UR5e's ready pose (upper arm up, forearm level, tool down) in the standard DH zero."""


def ur5e_style(directory, *, scale: float = 1.0, gripper: bool | str = False, motors: bool = False) -> Path:
    """A 6-joint UR5e-style arm in ``directory/universal_robots_ur5e/ur5e.xml``.

    UR5e standard DH geometry; classes ``ur5e``, ``ur5e/size3``, ``ur5e/size3_limited``,
    ``ur5e/size1``, ``ur5e/visual`` (OBJ meshes in ``assets/``), ``ur5e/collision``
    (capsules and cylinders); ``general`` affine actuators named ``shoulder_pan`` ... for
    joints ``shoulder_pan_joint`` ...; the base turned half a turn about z, as Menagerie's
    is; the flange site ``attachment_site`` (z out of the flange) on ``wrist_3_link``; a
    ``home`` keyframe with ctrl. A 0.12 m tool is ``tip_offset=(0, 0, 0.12)`` from the site.

    ``scale``: the whole arm that many times its size (masses with the volume, servo gains
    and force limits with the fourth power: a small arm has weak servos), written as
    ``small_ur/small_ur.xml`` (model ``small_ur``) when it is not 1. ``gripper``: a parallel
    gripper on the flange (``ur5e_gripper.xml``, model ``ur5e_gripper``): a palm body
    ``gripper_base``, fingers ``left_pad``/``right_pad`` on slide joints each driven by its
    own ``position`` actuator, and a TCP site ``pinch`` between the fingers that the
    fingertips reach ``GRIPPER_PAST`` past (see ``_gripper``). ``gripper="wide"``: the same
    with fingers as wide as a Robotiq-style pad over their whole length
    (``ur5e_wide_gripper.xml``, model ``ur5e_wide_gripper``): too wide for a 1 cm door.
    ``motors``: torque motors only (``ur5e_motors.xml``, model ``ur5e_motors``): a ``motor``
    actuator per joint (gear 1, control range the UR5e's joint torque limits, 150 and 28 N m)
    and no position servo, as a file written for torque control has; ``home`` keyframe
    without ctrl.
    """
    k = float(scale)
    model = "ur5e" if k == 1.0 else "small_ur"
    folder = Path(directory) / ("universal_robots_ur5e" if k == 1.0 else "small_ur")
    meshes = _Meshes(folder / "assets", "obj")
    frames = [(tuple(k * np.asarray(pos)), alpha) for pos, alpha in ur5e_frames()]
    n = len(frames)
    radii = tuple(k * r for r in UR5E_RADII)
    pedestal = k * UR5E_PEDESTAL
    meshes.add("base_0", *box_mesh((0, 0, 0), (0, 0, pedestal), 0.07 * k))
    body_xml = []
    indent = "    "
    for i in range(n):
        pos, alpha = frames[i]
        child = np.array(frames[i + 1][0]) if i + 1 < n else np.array((0.0, 0.0, k * UR5E_DH["d"][5]))
        r = radii[i]
        cls = "ur5e/size1" if i >= 3 else ("ur5e/size3_limited" if i == 2 else "ur5e/size3")
        pad = indent + "  " * (i + 1)
        body_xml.append(f'{pad}<body name="{UR5E_BODIES[i]}" pos="{_v(pos)}" quat="{_v(_quat_rx(alpha))}">')
        body_xml.append(f"{pad}  {cylinder_inertial(UR5E_MASSES[i] * k ** 3, r * 0.8, (0, 0, 0), child)}")
        body_xml.append(f'{pad}  <joint name="{UR5E_JOINTS[i]}" class="{cls}"/>')
        hub = meshes.add(f"{UR5E_BODIES[i].replace('_link', '')}_0", *prism_mesh(r, r))
        body_xml.append(f'{pad}  <geom mesh="{hub}" material="urblue" class="ur5e/visual"/>')
        start = np.zeros(3)
        if i == 0:  # the shoulder column stands on the base's pedestal
            start = np.array((0.0, 0.0, pedestal + 0.01 * k + r * 0.7))
        else:
            body_xml.append(f'{pad}  <geom class="ur5e/collision" type="cylinder" size="{_f(r)} {_f(r * 0.8)}"/>')
        if np.linalg.norm(child) > 1e-9:
            bar = meshes.add(f"{UR5E_BODIES[i].replace('_link', '')}_1", *box_mesh(start, child, r * 0.7))
            body_xml.append(f'{pad}  <geom mesh="{bar}" material="linkgray" class="ur5e/visual"/>')
            cls_col = "ur5e/eef_collision" if i == n - 1 else "ur5e/collision"
            end = _shorten(start, child, radii[i + 1] + r * 0.7 if i + 1 < n else 0.0)
            body_xml.append(f'{pad}  <geom class="{cls_col}" size="{_f(r * 0.7)}" '
                            f'fromto="{_v(start)} {_v(end)}"/>')
    flange = k * UR5E_DH["d"][5]
    pad = indent + "  " * n
    body_xml.append(f'{pad}  <site name="attachment_site" pos="0 0 {_f(flange)}"/>')
    if gripper:
        model = "ur5e_wide_gripper" if gripper == "wide" else "ur5e_gripper"
        body_xml += _gripper(pad + "  ", flange, wide=gripper == "wide")
    for i in range(n, 0, -1):
        body_xml.append(f"{indent + '  ' * i}</body>")
    actuators = []
    for i, (act, joint) in enumerate(zip(UR5E_ACTUATORS, UR5E_JOINTS)):
        cls = "ur5e/size1" if i >= 3 else ("ur5e/size3_limited" if i == 2 else "ur5e/size3")
        if motors:
            torque = _f((28 if i >= 3 else 150) * k ** 4)
            actuators.append(f'    <motor class="{cls}" name="{act}" joint="{joint}" ctrlrange="-{torque} {torque}"/>')
        else:
            actuators.append(f'    <general class="{cls}" name="{act}" joint="{joint}"/>')
    if motors:
        model = "ur5e_motors"
    home = list(UR5E_HOME)
    if gripper:
        actuators += [f'    <position class="gripper/finger" name="{side}_finger" joint="{side}_finger_joint"/>'
                      for side in ("left", "right")]
        home += [0.0, 0.0]
    g3, g1 = 2000 * k ** 4, 500 * k ** 4  # servo gains and force limits of a smaller arm
    f3, f1 = 150 * k ** 4, 28 * k ** 4
    text = f"""<mujoco model="{model}">
  <compiler angle="radian" meshdir="assets" autolimits="true"/>

  <option integrator="implicitfast"/>

  <default>
    <default class="ur5e">
      <material specular="0.5" shininess="0.25"/>
      <joint axis="0 0 1" range="-6.28319 6.28319" armature="0.1"/>
      <general gaintype="fixed" biastype="affine" ctrlrange="-6.2831 6.2831" gainprm="{_f(g3)}"
        biasprm="0 -{_f(g3)} -{_f(g3 / 5)}" forcerange="-{_f(f3)} {_f(f3)}"/>
      <default class="ur5e/size3">
        <default class="ur5e/size3_limited">
          <joint range="-3.1415 3.1415"/>
          <general ctrlrange="-3.1415 3.1415"/>
        </default>
      </default>
      <default class="ur5e/size1">
        <general gainprm="{_f(g1)}" biasprm="0 -{_f(g1)} -{_f(g1 / 5)}" forcerange="-{_f(f1)} {_f(f1)}"/>
      </default>
      <default class="ur5e/visual">
        <geom type="mesh" contype="0" conaffinity="0" group="2"/>
      </default>
      <default class="ur5e/collision">
        <geom type="capsule" group="3"/>
        <default class="ur5e/eef_collision">
          <geom type="cylinder"/>
        </default>
      </default>
      <site size="0.001" rgba="0.5 0.5 0.5 0.3" group="4"/>
    </default>{GRIPPER_DEFAULTS if gripper else ""}
  </default>

  <asset>
    <material class="ur5e" name="black" rgba="0.033 0.033 0.033 1"/>
    <material class="ur5e" name="linkgray" rgba="0.82 0.82 0.82 1"/>
    <material class="ur5e" name="urblue" rgba="0.49 0.678 0.8 1"/>
{chr(10).join(meshes.assets)}
  </asset>

  <worldbody>
    <light name="spotlight" mode="targetbodycom" target="wrist_2_link" pos="0 -1 2"/>
    <body name="base" quat="0 0 0 1" childclass="ur5e">
      <inertial mass="{_f(4.0 * k ** 3)}" pos="0 0 {_f(0.02 * k)}" diaginertia="0.00443 0.00443 0.0072"/>
      <geom mesh="base_0" material="black" class="ur5e/visual"/>
      <geom class="ur5e/collision" type="cylinder" size="{_f(0.075 * k)} {_f(pedestal / 2)}"
        pos="0 0 {_f(pedestal / 2)}"/>
{chr(10).join(body_xml)}
    </body>
  </worldbody>

  <actuator>
{chr(10).join(actuators)}
  </actuator>

  <keyframe>
    <key name="home" qpos="{_v(home)}"{"" if motors else f' ctrl="{_v(home)}"'}/>
  </keyframe>
</mujoco>
"""
    return _write(folder, model, text)


GRIPPER_FINGER = 0.06
"""Length of each gripper finger below the palm (m); its last ``GRIPPER_TIP`` is narrow."""
GRIPPER_TIP = 0.022
GRIPPER_PALM = 0.04
"""The palm's depth (m) from the flange to where the fingers start."""
GRIPPER_PAST = 0.015
"""How far the fingertips reach past the TCP site ``pinch`` (m)."""
GRIPPER_TCP = GRIPPER_PALM + GRIPPER_FINGER - GRIPPER_PAST
"""The TCP site's depth below the flange (m)."""
GRIPPER_DEFAULTS = """
    <default class="gripper">
      <default class="gripper/finger">
        <joint type="slide" axis="0 1 0" range="0 0.03" armature="0.001" damping="1"/>
        <position kp="100" ctrlrange="0 0.03" forcerange="-20 20"/>
        <geom type="box" group="3" friction="1 0.005 0.0001"/>
      </default>
    </default>"""


WIDE_PAD = 0.011
"""Half the width (m) of the wide gripper's fingers: 22 mm across, a Robotiq-style pad."""


def _gripper(pad: str, flange: float, wide: bool = False) -> list[str]:
    """A parallel gripper on a flange ``flange`` along z from the last body's origin: a palm,
    two fingers on slides (closed at 0), narrow for their last ``GRIPPER_TIP`` (a closed
    gripper is 7 mm by 6 mm there), and the TCP site ``pinch`` ``GRIPPER_PAST`` short of the
    fingertips."""
    upper = GRIPPER_FINGER - GRIPPER_TIP
    out = [f'{pad}<body name="gripper_base" pos="0 0 {_f(flange)}" childclass="gripper">',
           f'{pad}  <inertial mass="0.5" pos="0 0 0.02" diaginertia="0.0004 0.0004 0.0003"/>',
           f'{pad}  <geom class="ur5e/collision" type="box" size="0.035 0.03 {_f(GRIPPER_PALM / 2)}" '
           f'pos="0 0 {_f(GRIPPER_PALM / 2)}"/>',
           f'{pad}  <site name="pinch" pos="0 0 {_f(GRIPPER_TCP)}"/>']
    for side, sign in (("left", 1), ("right", -1)):
        out += [f'{pad}  <body name="{side}_pad" pos="0 0 {_f(GRIPPER_PALM)}">',
                f'{pad}    <inertial mass="0.03" pos="0 {_f(sign * 0.006)} 0.03" diaginertia="1e-5 1e-5 2e-6"/>',
                f'{pad}    <joint name="{side}_finger_joint" class="gripper/finger"'
                f'{"" if sign > 0 else chr(32) + "axis=" + chr(34) + "0 -1 0" + chr(34)}/>',
                f'{pad}    <geom class="gripper/finger" size="{_f(WIDE_PAD if wide else 0.008)} 0.004 {_f(upper / 2)}" '
                f'pos="0 {_f(sign * 0.006)} {_f(upper / 2)}"/>',
                f'{pad}    <geom class="gripper/finger" size="{_f(WIDE_PAD if wide else 0.003)} 0.0015 '
                f'{_f(GRIPPER_TIP / 2)}" '
                f'pos="0 {_f(sign * 0.002)} {_f(upper + GRIPPER_TIP / 2)}"/>',
                f"{pad}  </body>"]
    return out + [f"{pad}</body>"]


# --------------------------------------------------------------------------- Panda style

PANDA_MASSES = (4.970684, 0.646926, 3.228604, 3.587895, 1.225946, 1.666555, 0.735522)
"""The Panda's published link masses (kg), links 1-7."""
PANDA_RADII = (0.06, 0.06, 0.055, 0.055, 0.04, 0.04, 0.032)
PANDA_GAINS = (4500, 4500, 3500, 3500, 2000, 2000, 2000)
PANDA_HOME = (0.0, 0.0, 0.0, -1.57079, 0.0, 1.57079, -0.7853)
"""The Panda's ready pose: elbow up, hand pointing down."""
FINGER_LENGTH = 0.045
HAND_TO_FINGERS = 0.0584
PANDA_TCP = HAND_TO_FINGERS + FINGER_LENGTH  # 0.1034: the fingertips, from the hand frame
FINGERTIP = 0.02
"""The last 2 cm of each finger is a narrow tip (6 mm wide, 3 mm thick): the closed gripper
fits through a 1-cell door between 2 cm walls, as a stylus does, with the wide part above
the walls when the fingertips are at the tip height."""
FINGER_UPPER = FINGER_LENGTH - FINGERTIP


def panda_style(directory, hand: bool = True, tcp: bool = False) -> Path:
    """A 7-joint Panda-style arm: ``directory/franka_emika_panda/panda.xml`` (with hand) or
    ``panda_nohand.xml`` (without).

    Panda modified DH geometry; classes ``panda``, ``panda/finger`` (sets the fingers'
    joint type to slide), ``panda/visual`` (STL and OBJ meshes in ``assets/``),
    ``panda/collision``; ``general`` affine actuators ``actuator1..7`` for joints
    ``joint1..7``. With ``hand``: a body ``hand`` on the flange (turned -45 degrees about
    its z, as the real one), fingers ``left_finger``/``right_finger`` on slide joints
    ``finger_joint1``/``finger_joint2`` coupled by the fixed tendon ``split`` (driven by
    ``actuator8``) and an equality constraint; no site at all; keyframe ``home`` with 9
    values, the gripper closed. The fingertips are ``tip_body="hand",
    tip_offset=(0, 0, 0.1034)``. With ``tcp`` (and ``hand``): ``panda_tcp.xml``, the same with a
    TCP site ``tcp`` on the hand between the fingers, which reach ``FINGERTIP`` (2 cm) past
    it, as some files put their TCP. Without ``hand``: the flange site ``attachment_site`` and a
    7-value ``home``; a 0.1 m tool is ``tip_offset=(0, 0, 0.1)`` from the site.
    """
    folder = Path(directory) / "franka_emika_panda"
    meshes = _Meshes(folder / "assets", "stl")
    frames = panda_frames()
    n = len(frames)
    meshes.add("link0_c", *prism_mesh(0.08, 0.025), named=True)
    meshes.add("link0_0", *prism_mesh(0.08, 0.025), fmt="obj")
    body_xml = []
    indent = "    "
    for i in range(n):
        pos, alpha = frames[i]
        child = np.array(frames[i + 1][0]) if i + 1 < n else np.array((0.0, 0.0, PANDA_FLANGE))
        r = PANDA_RADII[i]
        pad = indent + "  " * (i + 1)
        rng = ""
        if (PANDA_LIMITS[0][i], PANDA_LIMITS[1][i]) != (-2.8973, 2.8973):
            rng = f' range="{_f(PANDA_LIMITS[0][i])} {_f(PANDA_LIMITS[1][i])}"'
        body_xml.append(f'{pad}<body name="link{i + 1}" pos="{_v(pos)}" quat="{_v(_quat_rx(alpha))}">')
        body_xml.append(f"{pad}  {cylinder_inertial(PANDA_MASSES[i], r * 0.8, (0, 0, 0), child)}")
        body_xml.append(f'{pad}  <joint name="joint{i + 1}"{rng}/>')
        visual = meshes.add(f"link{i + 1}", *box_mesh((0, 0, 0), child, r * 0.75), fmt="obj")
        body_xml.append(f'{pad}  <geom material="white" mesh="{visual}" class="panda/visual"/>')
        body_xml.append(f'{pad}  <geom class="panda/collision" type="cylinder" size="{_f(r)} {_f(r * 0.8)}"/>')
        if i == 0:  # the column from the base up to the shoulder turns with joint 1
            top = -frames[0][0][2]
            body_xml.append(f'{pad}  <geom class="panda/collision" size="{_f(r * 0.8)}" '
                            f'fromto="0 0 {_f(top + 0.06 + r * 0.8)} 0 0 {_f(-r)}"/>')
        elif np.linalg.norm(child) > 1e-9:
            # clear of the next two joints' housings, which meet at the Panda's wrist
            end = _shorten((0, 0, 0), child, max(PANDA_RADII[i + 1:i + 3]) + r * 0.7 + 0.005 if i + 1 < n else 0.0)
            body_xml.append(f'{pad}  <geom class="panda/collision" size="{_f(r * 0.7)}" '
                            f'fromto="0 0 0 {_v(end)}"/>')
    pad = indent + "  " * n
    if hand:
        meshes.add("hand_c", *box_mesh((0, -0.1, 0.033), (0, 0.1, 0.033), 0.03), named=True)
        meshes.add("finger_0", *box_mesh((0, 0.0065, 0), (0, 0.0065, FINGER_UPPER), 0.005), fmt="obj")
        meshes.add("finger_1", *box_mesh((0, 0.002, FINGER_UPPER), (0, 0.002, FINGER_LENGTH), 0.0015), fmt="obj")
        body_xml += [
            f'{pad}  <body name="hand" pos="0 0 {_f(PANDA_FLANGE)}" quat="{_v(_quat_rz(-math.pi / 4))}">',
            f'{pad}    <inertial mass="0.73" pos="-0.01 0 0.03" diaginertia="0.001 0.0025 0.0017"/>',
            f'{pad}    <geom mesh="hand_c" material="white" class="panda/visual"/>',
            f'{pad}    <geom class="panda/collision" type="box" size="0.03 0.1 0.028" pos="0 0 0.03"/>',
        ]
        if tcp:
            body_xml.append(f'{pad}    <site name="tcp" pos="0 0 {_f(PANDA_TCP - FINGERTIP)}"/>')
        for side, quat, joint in (("left", None, 1), ("right", (0, 0, 0, 1), 2)):
            q = f' quat="{_v(quat)}"' if quat else ""
            body_xml += [
                f'{pad}    <body name="{side}_finger" pos="0 0 {_f(HAND_TO_FINGERS)}"{q}>',
                f'{pad}      <inertial mass="0.015" pos="0 0.0065 0.0225" diaginertia="2.375e-6 2.375e-6 7.5e-7"/>',
                f'{pad}      <joint name="finger_joint{joint}" class="panda/finger"/>',
                f'{pad}      <geom mesh="finger_0" material="black" class="panda/visual"/>',
                f'{pad}      <geom mesh="finger_1" material="black" class="panda/visual"/>',
                f'{pad}      <geom class="panda/collision" type="box" size="0.008 0.005 {_f(FINGER_UPPER / 2)}" '
                f'pos="0 0.0065 {_f(FINGER_UPPER / 2)}"/>',
                f'{pad}      <geom class="panda/fingertip_pad" size="0.003 0.0015 {_f(FINGERTIP / 2)}" '
                f'pos="0 0.002 {_f(FINGER_LENGTH - FINGERTIP / 2)}"/>',
                f"{pad}    </body>",
            ]
        body_xml.append(f"{pad}  </body>")
    else:
        body_xml.append(f'{pad}  <site name="attachment_site" pos="0 0 {_f(PANDA_FLANGE)}" '
                        f'quat="{_v(_quat_rz(-math.pi / 4))}"/>')
    for i in range(n, 0, -1):
        body_xml.append(f"{indent + '  ' * i}</body>")
    actuators = []
    for i, kp in enumerate(PANDA_GAINS):
        extra = ' forcerange="-12 12"' if i >= 4 else ""
        if (PANDA_LIMITS[0][i], PANDA_LIMITS[1][i]) != (-2.8973, 2.8973):
            extra += f' ctrlrange="{_f(PANDA_LIMITS[0][i])} {_f(PANDA_LIMITS[1][i])}"'
        actuators.append(f'    <general class="panda" name="actuator{i + 1}" joint="joint{i + 1}" '
                         f'gainprm="{kp}" biasprm="0 -{kp} -{kp // 10}"{extra}/>')
    gripper = ""
    home_q, home_ctrl = list(PANDA_HOME), list(PANDA_HOME)
    if hand:
        # ctrl 0..255 spans the finger opening 0..0.04 m: gain 0.04 * 100 / 255 per unit
        actuators.append('    <general class="panda" name="actuator8" tendon="split" forcerange="-100 100" '
                         'ctrlrange="0 255" gainprm="0.0156863 0 0" biasprm="0 -100 -10"/>')
        gripper = """
  <tendon>
    <fixed name="split">
      <joint joint="finger_joint1" coef="0.5"/>
      <joint joint="finger_joint2" coef="0.5"/>
    </fixed>
  </tendon>

  <equality>
    <joint joint1="finger_joint1" joint2="finger_joint2" solimp="0.95 0.99 0.001" solref="0.005 1"/>
  </equality>
"""
        home_q += [0.0, 0.0]
        home_ctrl += [0.0]
    text = f"""<mujoco model="panda">
  <compiler angle="radian" meshdir="assets" autolimits="true"/>

  <option integrator="implicitfast"/>

  <default>
    <default class="panda">
      <material specular="0.5" shininess="0.25"/>
      <joint armature="0.1" damping="1" axis="0 0 1" range="-2.8973 2.8973"/>
      <general dyntype="none" biastype="affine" ctrlrange="-2.8973 2.8973" forcerange="-87 87"/>
      <default class="panda/finger">
        <joint axis="0 1 0" type="slide" range="0 0.04" armature="0.001" damping="0.1"/>
      </default>
      <default class="panda/visual">
        <geom type="mesh" contype="0" conaffinity="0" group="2"/>
      </default>
      <default class="panda/collision">
        <geom type="capsule" group="3"/>
        <default class="panda/fingertip_pad">
          <geom type="box" friction="1 0.005 0.0001"/>
        </default>
      </default>
    </default>
  </default>

  <asset>
    <material class="panda" name="white" rgba="1 1 1 1"/>
    <material class="panda" name="black" rgba="0.25 0.25 0.25 1"/>
{chr(10).join(meshes.assets)}
  </asset>

  <worldbody>
    <light name="top" pos="0 0 2" mode="trackcom"/>
    <body name="link0" childclass="panda">
      <inertial mass="0.629769" pos="-0.041018 -0.00014 0.049974"
        fullinertia="0.00315 0.00388 0.004285 8.2904e-7 0.00015 8.2299e-6"/>
      <geom mesh="link0_0" material="white" class="panda/visual" pos="0 0 0.025"/>
      <geom mesh="link0_c" class="panda/collision" type="mesh" pos="0 0 0.025"/>
{chr(10).join(body_xml)}
    </body>
  </worldbody>
{gripper}
  <actuator>
{chr(10).join(actuators)}
  </actuator>

  <keyframe>
    <key name="home" qpos="{_v(home_q)}" ctrl="{_v(home_ctrl)}"/>
  </keyframe>
</mujoco>
"""
    return _write(folder, ("panda_tcp" if tcp else "panda") if hand else "panda_nohand", text)


# --------------------------------------------------------------------------- SO100 style

SO100_SCALE = 1.8
"""The SO-ARM100's proportions at 1.8 times its size (a WidowX-200-sized 5-joint arm): the
real one's tool cannot point down over more than a third of a 0.51 m table from beside it."""
SO100_JAW = 0.1 * SO100_SCALE
"""Length of the fixed jaw from the wrist-roll frame (``Fixed_Jaw``) to its tip, along z."""
SO100_STAND = ((1.2, -0.8, 0.75), math.pi / 2)
"""The arm stands on a body ``stand`` far from the file's origin: 1.2 m, -0.8 m, 0.75 m up,
turned a quarter turn (a base far from the table, as in a file written for a whole scene)."""
SO100_JAW_TIP = 0.02
"""The jaws' last 2 cm are narrow (3 mm by 6 mm each): closed, they fit through a 1-cell door."""


def so100_style(directory) -> Path:
    """A 5-joint SO-ARM100-style arm with a jaw: ``directory/trs_so_arm100/so_arm100.xml``.

    Joints ``Rotation`` (vertical), ``Pitch``, ``Elbow``, ``Wrist_Pitch`` (about x),
    ``Wrist_Roll`` (about the tool axis) on bodies ``Rotation_Pitch``, ``Upper_Arm``,
    ``Lower_Arm``, ``Wrist_Pitch_Roll``, ``Fixed_Jaw``; a hinge ``Jaw`` on ``Moving_Jaw``.
    Axes and ranges are set by one default class per joint; ``position`` actuators named
    like the joints (``kp``/``dampratio``); STL meshes in ``assets/`` (``meshdir="assets/"``);
    no site and no keyframe. qpos0 is an L pose: upper arm up, forearm level, jaws down.
    The fixed jaw's tip is ``tip_body="Fixed_Jaw", tip_offset=(0, 0, SO100_JAW)`` (0.18 m),
    on the roll axis. The base is meant to stand beside the table, but the file puts it on a
    body ``stand`` 1.5 m from the origin and 0.75 m up (``SO100_STAND``).
    """
    s = SO100_SCALE
    folder = Path(directory) / "trs_so_arm100"
    meshes = _Meshes(folder / "assets", "stl")
    base_h, shoulder_h = 0.03 * s, 0.09 * s
    upper, upper_off, fore, wrist = 0.113 * s, 0.028 * s, 0.135 * s, 0.06 * s
    parts = {  # body: (mass kg at this scale, radius, bar end in the body frame)
        "Base": (0.5 * s ** 3, 0.03 * s, (0, 0, base_h)),
        "Rotation_Pitch": (0.119 * s ** 3, 0.022 * s, (0, 0, shoulder_h)),
        "Upper_Arm": (0.162 * s ** 3, 0.018 * s, (0, upper_off, upper)),
        "Lower_Arm": (0.148 * s ** 3, 0.016 * s, (0, fore, 0)),
        "Wrist_Pitch_Roll": (0.066 * s ** 3, 0.014 * s, (0, 0, -wrist)),
        "Fixed_Jaw": (0.093 * s ** 3, 0.012 * s, (-0.008, 0, SO100_JAW)),
        "Moving_Jaw": (0.020 * s ** 3, 0.005, (0, 0, 0.7 * SO100_JAW)),
    }

    def geoms(body, pad):
        mass, r, end = parts[body]
        mesh = meshes.add(body, *box_mesh((0, 0, 0), end, r))
        out = [f"{pad}{cylinder_inertial(mass, r, (0, 0, 0), end)}" if body != "Base" else "",
               f'{pad}<geom class="so_arm100/visual" mesh="{mesh}"/>']
        if body == "Fixed_Jaw":  # the fixed jaw is a finger beside the roll axis, narrow at its tip
            upper = SO100_JAW - SO100_JAW_TIP
            out.append(f'{pad}<geom class="so_arm100/finger_collision" size="0.004 0.01 {_f(upper * 0.3)}" '
                       f'pos="-0.008 0 {_f(upper * 0.7)}"/>')
            out.append(f'{pad}<geom class="so_arm100/finger_collision" size="0.0015 0.003 {_f(SO100_JAW_TIP / 2)}" '
                       f'pos="-0.002 0 {_f(SO100_JAW - SO100_JAW_TIP / 2)}"/>')
            out.append(f'{pad}<geom class="so_arm100/collision" size="{_f(r)}" '
                       f'fromto="0 0 0 0 0 {_f(0.2 * SO100_JAW)}"/>')
        elif body == "Moving_Jaw":  # hinged 8 mm beside the roll axis, its tip meeting the fixed one's
            upper = 0.7 * SO100_JAW - SO100_JAW_TIP
            out.append(f'{pad}<geom class="so_arm100/finger_collision" size="0.004 0.01 {_f(upper / 2)}" '
                       f'pos="0 0 {_f(upper / 2)}"/>')
            out.append(f'{pad}<geom class="so_arm100/finger_collision" size="0.0015 0.003 {_f(SO100_JAW_TIP / 2)}" '
                       f'pos="-0.006 0 {_f(0.7 * SO100_JAW - SO100_JAW_TIP / 2)}"/>')
        else:
            out.append(f'{pad}<geom class="so_arm100/collision" size="{_f(r)}" fromto="0 0 0 {_v(end)}"/>')
        return [line for line in out if line]

    xml = ['    <body name="Base" childclass="so_arm100" pos="0 0 0">',
           f'      <inertial pos="0 0 {_f(base_h / 2)}" mass="{_f(parts["Base"][0])}" '
           f'diaginertia="{_f(0.002 * s ** 5)} {_f(0.002 * s ** 5)} {_f(0.002 * s ** 5)}"/>',
           *geoms("Base", "      "),
           f'      <body name="Rotation_Pitch" pos="0 0 {_f(base_h)}">',
           '        <joint name="Rotation" class="so_arm100/Rotation"/>',
           *geoms("Rotation_Pitch", "        "),
           f'        <body name="Upper_Arm" pos="0 0 {_f(shoulder_h)}">',
           '          <joint name="Pitch" class="so_arm100/Pitch"/>',
           *geoms("Upper_Arm", "          "),
           f'          <body name="Lower_Arm" pos="0 {_f(upper_off)} {_f(upper)}">',
           '            <joint name="Elbow" class="so_arm100/Elbow"/>',
           *geoms("Lower_Arm", "            "),
           f'            <body name="Wrist_Pitch_Roll" pos="0 {_f(fore)} 0">',
           '              <joint name="Wrist_Pitch" class="so_arm100/Wrist_Pitch"/>',
           *geoms("Wrist_Pitch_Roll", "              "),
           f'              <body name="Fixed_Jaw" pos="0 0 {_f(-wrist)}" quat="0 1 0 0">',
           '                <joint name="Wrist_Roll" class="so_arm100/Wrist_Roll"/>',
           *geoms("Fixed_Jaw", "                "),
           f'                <body name="Moving_Jaw" pos="0.008 0 {_f(0.3 * SO100_JAW)}">',
           '                  <joint name="Jaw" class="so_arm100/Jaw"/>',
           *geoms("Moving_Jaw", "                  "),
           "                </body>", "              </body>", "            </body>",
           "          </body>", "        </body>", "      </body>", "    </body>"]
    (sx, sy, sz), stand_yaw = SO100_STAND
    xml = [f'    <body name="stand" pos="{_v((sx, sy, sz))}" quat="{_v(_quat_rz(stand_yaw))}">',
           *("  " + line for line in xml), "    </body>"]
    joints = ("Rotation", "Pitch", "Elbow", "Wrist_Pitch", "Wrist_Roll", "Jaw")
    actuators = [f'    <position class="so_arm100/{j}" name="{j}" joint="{j}"/>' for j in joints]
    text = f"""<mujoco model="so_arm100">
  <compiler angle="radian" meshdir="assets/"/>

  <option cone="elliptic" impratio="10"/>

  <asset>
    <material name="orange" rgba="1.0 0.331 0.0 1.0" specular="0.1" shininess="0.1"/>
{chr(10).join(meshes.assets)}
  </asset>

  <default>
    <default class="so_arm100">
      <joint frictionloss="0.1" armature="0.1" damping="0.5"/>
      <position kp="300" dampratio="1" forcerange="-35 35"/>
      <default class="so_arm100/Rotation">
        <joint axis="0 0 1" range="-2.2 2.2"/>
        <position ctrlrange="-2.2 2.2"/>
      </default>
      <default class="so_arm100/Pitch">
        <joint axis="1 0 0" range="-2.0 1.35"/>
        <position ctrlrange="-2.0 1.35"/>
      </default>
      <default class="so_arm100/Elbow">
        <joint axis="1 0 0" range="-1.5 1.65"/>
        <position ctrlrange="-1.5 1.65"/>
      </default>
      <default class="so_arm100/Wrist_Pitch">
        <joint axis="1 0 0" range="-2.0 1.8"/>
        <position ctrlrange="-2.0 1.8"/>
      </default>
      <default class="so_arm100/Wrist_Roll">
        <joint axis="0 0 1" range="-3.14158 3.14158"/>
        <position ctrlrange="-3.14158 3.14158"/>
      </default>
      <default class="so_arm100/Jaw">
        <joint axis="0 1 0" range="-0.2 2.0" armature="0.01"/>
        <position ctrlrange="-0.2 2.0" kp="20"/>
      </default>
      <default class="so_arm100/visual">
        <geom type="mesh" contype="0" conaffinity="0" density="0" group="2" material="orange"/>
      </default>
      <default class="so_arm100/collision">
        <geom group="3" type="capsule"/>
        <default class="so_arm100/finger_collision">
          <geom type="box" solimp="2 1 0.01" solref="0.01 1" friction="1 0.005 0.0001"/>
        </default>
      </default>
    </default>
  </default>

  <worldbody>
{chr(10).join(xml)}
  </worldbody>

  <actuator>
{chr(10).join(actuators)}
  </actuator>

  <contact>
    <exclude body1="Base" body2="Rotation_Pitch"/>
  </contact>
</mujoco>
"""
    return _write(folder, "so_arm100", text)


# --------------------------------------------------------------------------- planar 5, straight

PLANAR5_LINKS = (0.09, 0.075, 0.06, 0.045, 0.03)  # 0.30 m in all
PLANAR5_LIMITS = (2.9, 2.6, 2.6, 2.3, 2.0)
PLANAR5_HEIGHT = 0.12
PLANAR5_DROP = 0.02
PLANAR5_TIP_CLEARANCE = 0.004


PEN_RADIUS = 0.003
"""The round pen's radius (m): its round end reaches this far past the site at the end of its axis."""
PEN_SITE = 0.001
"""The pen's site is this far above the base frame's z = 0 (m): its round end 2 mm below it."""


WIDE_PEN_RADIUS = 0.006
"""The wide pen's radius (m): 12 mm across, wider than a 1 cm door."""


def planar5_straight(directory, pen: bool = False, pen_radius: float = PEN_RADIUS, scale: float = 1.0) -> Path:
    """A planar 5-joint arm (every joint axis vertical): ``directory/planar5/planar5.xml``.

    Links ``link1..link5`` (0.09, 0.075, 0.06, 0.045, 0.03 m; 0.30 m in all) stacked
    0.02 m apart from 0.12 m above the base frame down; joints ``j1..j5``; a body
    ``stylus`` at the end of ``link5`` whose origin is the stylus point, 4 mm above the
    base frame's z = 0; no site, no keyframe: qpos0 is the straight, singular arm.
    ``position`` actuators named ``servo1..servo5``; OBJ meshes in ``meshes/``.
    With the base frame on the tabletop (z = 0) the stylus hovers 4 mm above the table;
    hang it over the table anywhere its 0.30 m reach covers.

    ``pen``: ``planar5_pen.xml`` (model ``planar5_pen``), the same arm holding a pen, a
    capsule of radius ``PEN_RADIUS`` whose axis ends at the site ``pen_tip`` ``PEN_SITE`` above
    the base frame's z = 0: its round end reaches ``PEN_RADIUS`` past the site, into the table
    with the base frame on the tabletop (and with the site 2 mm above it).

    ``pen_radius`` and ``scale`` (the links' lengths) other than the defaults write
    ``planar5_wide_pen.xml`` (model ``planar5_wide_pen``): the wide pen is 12 mm across.
    """
    wide = pen and (pen_radius != PEN_RADIUS or scale != 1.0)
    model_name = "planar5_wide_pen" if wide else ("planar5_pen" if pen else "planar5")
    links = tuple(scale * v for v in PLANAR5_LINKS)
    folder = Path(directory) / "planar5"
    meshes = _Meshes(folder / "meshes", "obj")
    n = len(links)
    xml = ['    <body name="base" childclass="planar5">',
           f'      <geom class="planar5/collision" type="cylinder" size="0.03 0.02" '
           f'pos="0 0 {_f(PLANAR5_HEIGHT + 0.035)}"/>']
    pad = "    "
    z = PLANAR5_HEIGHT
    for i, length in enumerate(links, start=1):
        pad += "  "
        pos = f"0 0 {_f(PLANAR5_HEIGHT)}" if i == 1 else f"{_f(links[i - 2])} 0 {_f(-PLANAR5_DROP)}"
        if i > 1:
            z -= PLANAR5_DROP
        mesh = meshes.add(f"link{i}", *box_mesh((0, 0, 0), (length, 0, 0), 0.011))
        mass = 0.4 * length / 0.09 + 0.05
        xml += [f'{pad}<body name="link{i}" pos="{pos}">',
                f"{pad}  {cylinder_inertial(mass, 0.012, (0, 0, 0), (length, 0, 0))}",
                f'{pad}  <joint name="j{i}" range="{_f(-PLANAR5_LIMITS[i - 1])} {_f(PLANAR5_LIMITS[i - 1])}"/>',
                f'{pad}  <geom class="planar5/visual" mesh="{mesh}"/>',
                f'{pad}  <geom class="planar5/collision" size="0.012" fromto="0 0 0 {_f(length)} 0 0"/>']
        if i > 1:
            xml.append(f'{pad}  <geom class="planar5/collision" type="cylinder" size="0.016 0.02" '
                       f'pos="0 0 {_f(PLANAR5_DROP / 2)}"/>')
    stylus = z - (PEN_SITE if pen else PLANAR5_TIP_CLEARANCE)
    tool = (f'{pad}    <geom class="planar5/collision" size="{_f(pen_radius)}" fromto="0 0 0 0 0 {_f(stylus)}"/>',
            f'{pad}    <site name="pen_tip"/>') if pen else (
            f'{pad}    <geom class="planar5/collision" type="cylinder" size="0.0015" fromto="0 0 0 0 0 {_f(stylus)}"/>',)
    xml += [f'{pad}  <body name="{"pen" if pen else "stylus"}" pos="{_f(links[-1])} 0 {_f(-stylus)}">',
            f'{pad}    <inertial pos="0 0 {_f(stylus / 2)}" mass="0.01" diaginertia="2e-5 2e-5 1e-7"/>',
            *tool, f"{pad}  </body>"]
    for _ in range(n):
        xml.append(f"{pad}</body>")
        pad = pad[:-2]
    xml.append("    </body>")
    actuators = [f'    <position name="servo{i}" joint="j{i}" class="planar5" '
                 f'ctrlrange="{_f(-lim)} {_f(lim)}"/>' for i, lim in enumerate(PLANAR5_LIMITS, start=1)]
    text = f"""<mujoco model="{model_name}">
  <compiler angle="radian" meshdir="meshes" autolimits="true"/>
  <option integrator="implicitfast"/>
  <default>
    <default class="planar5">
      <joint type="hinge" axis="0 0 1" damping="0.5" armature="0.01"/>
      <position kp="20" dampratio="1"/>
      <default class="planar5/visual">
        <geom type="mesh" contype="0" conaffinity="0" group="2" rgba="0.3 0.45 0.7 1"/>
      </default>
      <default class="planar5/collision">
        <geom type="capsule" group="3"/>
      </default>
    </default>
  </default>
  <asset>
{chr(10).join(meshes.assets)}
  </asset>
  <worldbody>
{chr(10).join(xml)}
  </worldbody>
  <actuator>
{chr(10).join(actuators)}
  </actuator>
</mujoco>
"""
    return _write(folder, model_name, text)


# --------------------------------------------------------------------------- iiwa style, position servos

IIWA_FRAMES = ((0.0, 0.0, 0.1575), (0.0, 0.0, 0.2025), (0.0, 0.2045, 0.0), (0.0, 0.0, 0.2155),
               (0.0, 0.1845, 0.0), (0.0, 0.0, 0.2155), (0.0, 0.081, 0.0))
"""Each link's origin in its parent's frame (m): a KUKA LBR iiwa 14-style chain, 1.27 m tall."""
IIWA_TURNS = (None, "y", "y", "x", "y", "x", "y")
"""How each link is turned from its parent: ``y`` a half turn about y then a quarter about
x (the joint axis now along the parent's y), ``x`` a quarter turn about x back."""
IIWA_MASSES = (5.76, 6.35, 3.5, 3.5, 3.5, 1.8, 1.2)
IIWA_RADII = (0.07, 0.07, 0.065, 0.065, 0.055, 0.05, 0.045)
IIWA_LIMITS = (2.96, 2.09, 2.96, 2.09, 2.96, 2.09, 3.05)
IIWA_KP = (600, 600, 400, 400, 200, 100, 50)
"""Position gains (N m / rad) as a file exported for another simulator gives them: far below
what holds the arm against gravity within a cell (the UR5e-style file's are 2000 and 500);
held at home by these servos alone, the flange sags 7.7 cm in 4 s of plain ``mj_step``."""
IIWA_FORCE = (320, 320, 176, 176, 110, 40, 40)
IIWA_FLANGE = 0.045
IIWA_HOME = (0.0, 0.6, 0.0, -1.4, 0.0, 1.1, 0.0)


def iiwa_style(directory) -> Path:
    """A 7-joint iiwa-style arm as a file converted from another framework: ``directory/iiwa/iiwa14.xml``.

    No default classes; bodies ``link1..link7`` with joints ``joint1..joint7`` (every axis z
    in its own body, as the URDF had them), each link turned from its parent by a quaternion;
    ``position`` actuators ``joint1_position`` ... with the ``IIWA_KP`` gains, ``kv`` a tenth
    of them and the iiwa's torque limits as force ranges; a flange site ``attachment_site``
    (a 0.12 m tool is ``tip_offset=(0, 0, 0.12)``); a ``home`` keyframe, elbow bent; STL
    meshes in ``meshes/``.
    """
    folder = Path(directory) / "iiwa"
    meshes = _Meshes(folder / "meshes", "stl")
    half = math.sqrt(0.5)
    quats = {"y": (0.0, 0.0, half, half), "x": (half, half, 0.0, 0.0)}
    meshes.add("link_0", *prism_mesh(0.09, 0.05), named=True)
    xml = ['    <body name="link0">',
           '      <inertial pos="0 0 0.05" mass="5" diaginertia="0.05 0.06 0.03"/>',
           '      <geom type="mesh" mesh="link_0" contype="0" conaffinity="0" group="2" rgba="0.4 0.4 0.4 1"/>',
           '      <geom type="cylinder" size="0.09 0.05" pos="0 0 0.05" group="3"/>']
    pad = "      "
    n = len(IIWA_FRAMES)
    for i in range(n):
        child = np.array(IIWA_FRAMES[i + 1]) if i + 1 < n else np.array((0.0, 0.0, IIWA_FLANGE))
        turn = IIWA_TURNS[i]
        q = f' quat="{_v(quats[turn])}"' if turn else ""
        r = IIWA_RADII[i]
        start = np.array((0.0, 0.0, 0.1 - IIWA_FRAMES[0][2] + r)) if i == 0 else np.zeros(3)
        mesh = meshes.add(f"link_{i + 1}", *box_mesh(start, child, r * 0.8), named=True)
        end = _shorten(start, child, IIWA_RADII[i + 1] + r * 0.7 if i + 1 < n else 0.0)
        xml += [f'{pad}<body name="link{i + 1}" pos="{_v(IIWA_FRAMES[i])}"{q}>',
                f"{pad}  {cylinder_inertial(IIWA_MASSES[i], r * 0.8, (0, 0, 0), child)}",
                f'{pad}  <joint name="joint{i + 1}" type="hinge" axis="0 0 1" range="{_f(-IIWA_LIMITS[i])} '
                f'{_f(IIWA_LIMITS[i])}" damping="0.5" armature="0.1"/>',
                f'{pad}  <geom type="mesh" mesh="{mesh}" contype="0" conaffinity="0" group="2" rgba="1 0.42 0.04 1"/>',
                f'{pad}  <geom type="cylinder" size="{_f(r)} {_f(r * 0.8)}" group="3"/>' if i else "",
                f'{pad}  <geom type="capsule" size="{_f(r * 0.7)}" fromto="{_v(start)} {_v(end)}" group="3"/>']
        pad += "  "
    xml.append(f'{pad}<site name="attachment_site" pos="0 0 {_f(IIWA_FLANGE)}"/>')
    for _ in range(n + 1):
        pad = pad[:-2]
        xml.append(f"{pad}</body>")
    actuators = [f'    <position name="joint{i + 1}_position" joint="joint{i + 1}" kp="{kp}" kv="{kp / 10:g}" '
                 f'ctrlrange="{_f(-IIWA_LIMITS[i])} {_f(IIWA_LIMITS[i])}" forcerange="-{f} {f}"/>'
                 for i, (kp, f) in enumerate(zip(IIWA_KP, IIWA_FORCE))]
    text = f"""<mujoco model="iiwa14">
  <compiler angle="radian" meshdir="meshes"/>
  <option integrator="implicitfast"/>
  <asset>
{chr(10).join(meshes.assets)}
  </asset>
  <worldbody>
{chr(10).join(line for line in xml if line)}
  </worldbody>
  <actuator>
{chr(10).join(actuators)}
  </actuator>
  <keyframe>
    <key name="home" qpos="{_v(IIWA_HOME)}" ctrl="{_v(IIWA_HOME)}"/>
  </keyframe>
</mujoco>
"""
    return _write(folder, "iiwa14", text)


SMALL_UR_SCALE = 0.5
"""The small 6-joint arm: the UR5e-style arm at half its size (0.42 m of reach, servos 16 times weaker)."""

SUGGESTED = {
    "ur5e": dict(tip_site="attachment_site", tip_offset=(0.0, 0.0, 0.12), base_pos=(0.0, -0.42, 0.0),
                 base_yaw=math.pi / 2),
    "panda": dict(tip_body="hand", tip_offset=(0.0, 0.0, PANDA_TCP), base_pos=(0.0, -0.40, 0.0),
                  base_yaw=math.pi / 2),
    "panda_nohand": dict(tip_site="attachment_site", tip_offset=(0.0, 0.0, 0.1), base_pos=(0.0, -0.40, 0.0),
                         base_yaw=math.pi / 2),
    # the file frame's pose that puts the base at (-0.28, 0, 0) facing +x, past the stand
    "so100": dict(tip_body="Fixed_Jaw", tip_offset=(0.0, 0.0, SO100_JAW), base_pos=(0.92, -0.8, -0.75),
                  base_yaw=-math.pi),
    "planar5": dict(tip_body="stylus", tip_offset=(0.0, 0.0, 0.0), base_pos=(-0.03, 0.03, 0.0), base_yaw=0.0),
    # the tool points these files offer, with no mount: the fingers or the pen reach past them
    "panda_tcp": dict(tip_site="tcp"),
    "ur5e_gripper": dict(tip_site="pinch"),
    "ur5e_wide_gripper": dict(tip_site="pinch"),
    "small_ur": dict(tip_site="attachment_site", tip_offset=(0.0, 0.0, 0.06)),
    "planar5_pen": dict(tip_site="pen_tip"),
    "planar5_wide_pen": dict(tip_site="pen_tip"),
    "iiwa": dict(tip_site="attachment_site", tip_offset=(0.0, 0.0, 0.12)),
    "ur5e_motors": dict(tip_site="attachment_site", tip_offset=(0.0, 0.0, 0.12)),
}
"""A tip and a mount that work for each arm (cartesian, tool pointing down; planar5 also
joint). Measured with the project's compiler on copies of these files with the classes'
``/`` replaced and a site at the tip (the fingers held closed): ur5e reaches 100% of the
free cells, Table I 4/4; panda 96%, 4/4 (panda_nohand the same); so100 76%, 3/4; planar5
cartesian 77%, 3/4, and joint with a 0.35 rad step 92%, 4/4 (494,461 states, 51 s)."""


ALL = {"ur5e": ur5e_style, "panda": panda_style, "panda_nohand": lambda d: panda_style(d, hand=False),
       "so100": so100_style, "planar5": planar5_straight,
       "panda_tcp": lambda d: panda_style(d, tcp=True), "ur5e_gripper": lambda d: ur5e_style(d, gripper=True),
       "ur5e_wide_gripper": lambda d: ur5e_style(d, gripper="wide"),
       "small_ur": lambda d: ur5e_style(d, scale=SMALL_UR_SCALE), "planar5_pen": lambda d: planar5_straight(d, pen=True),
       "planar5_wide_pen": lambda d: planar5_straight(d, pen=True, pen_radius=WIDE_PEN_RADIUS, scale=2.0),
       "iiwa": iiwa_style, "ur5e_motors": lambda d: ur5e_style(d, motors=True)}
"""Every fixture by a short name."""


if __name__ == "__main__":  # write them all into a folder, to look at or load by hand
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "menagerie_like")
    for key, make in ALL.items():
        print(key, make(out))

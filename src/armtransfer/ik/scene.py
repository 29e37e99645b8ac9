"""An arm attached to the tabletop workspace with MuJoCo's ``MjSpec``, compiled to MuJoCo.

Any MJCF serial arm works as it is, MuJoCo Menagerie files included (class names with
``/``, a ``meshdir`` beside the file, ``general`` actuators, grippers driven by tendons):

- **The tool point** is a :class:`~armtransfer.ik.tool.Tool`: a site or a body of the file
  and an offset in its own frame. With an offset (or a body) the scene gets a site of its own
  there, ``tool_tip``, whose z axis is the tool's axis (the offset's direction).
- **The arm is the chain of joints from the base to the tool.** Joints off that chain
  (fingers, jaws) are held at their home value: each is removed and its body fixed where
  that value puts it, so it is not a degree of freedom. Joint types are read from the
  compiled model, default classes resolved. Tendons, equality constraints and sensors
  that refer to a removed joint go with it.
- **Actuators.** Position servos (an affine bias) on chain joints are kept, one per joint;
  every other actuator is dropped, and a chain joint left without one gets a servo of the
  scene's own, ``servo_<joint>``. So a replay can drive every chain joint, whatever
  actuators the file has.
- The file's keyframes are dropped (the scene keeps the arm's home separately), its options
  are the scene's, and the whole arm is attached under the prefix ``arm/`` at its mounting
  pose. A base mounted above the tabletop stands on a drawn column, ``pedestal``, that
  collides with nothing.
"""

from __future__ import annotations

import hashlib
import math
import os
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from armtransfer.errors import ArmModelError
from armtransfer.ik.tool import Tool
from armtransfer.ik.workspace import DEFAULT_CELL, WALL_HEIGHT, build_workspace
from armtransfer.io import check_input

if TYPE_CHECKING:  # the layout is passed in from armtransfer.tasks, never imported
    from armtransfer.worlds.layout import Layout

PREFIX = "arm/"
TOOL_SITE = "tool_tip"
SERVO_KP = 100.0
"""Stiffness of a servo the scene adds (N m/rad); a replay retunes every servo anyway."""
PEDESTAL = "pedestal"
"""Name of the column drawn under a base mounted above the tabletop (``mount_pos`` z > 0)."""
PEDESTAL_RADIUS = 0.05
"""Its radius (m). It is drawn only: it collides with nothing and is not part of the table."""


@dataclass(frozen=True)
class ArmScene:
    model: mujoco.MjModel
    xml: str
    """The composed scene's MJCF."""
    tip: str
    """Full name of the tool-tip site in the scene."""
    home: np.ndarray
    """The chain joints' home configuration."""
    lower: np.ndarray
    upper: np.ndarray
    env_geoms: np.ndarray
    """Boolean mask over geoms: True for table and wall geoms."""
    arm_geoms: np.ndarray
    """Boolean mask over geoms: True for the arm's geoms that move with a joint (a base fixed
    to the world may stand on the table; only moving parts can strike it)."""
    cell: float
    layout: Layout
    planar: bool
    """All joint axes vertical: the tip moves in a horizontal plane at a fixed height."""
    name: str = "arm"
    """The MJCF ``model`` attribute of the arm file."""
    chain: tuple[str, ...] = ()
    """The arm's joints, base to tool (names in the arm file)."""
    held: tuple[tuple[str, float], ...] = ()
    """Joints off the chain and the home value each is held at."""
    tool: Tool = Tool()
    clearance: float = 0.0
    """How far the tool's own geometry reaches past the tool point along the tool axis (m,
    at least 0): the point rides this much higher so that the lowest point clears the table
    as a bare point would (``tool_reach``)."""
    clearance_geom: str = ""
    """The geom that reaches farthest past the point ("" when none does)."""

    @property
    def nq(self) -> int:
        return int(self.model.nq)

    def digest(self) -> str:
        return hashlib.sha256(self.xml.encode()).hexdigest()


def base_footing(model: mujoco.MjModel, qpos: np.ndarray) -> tuple[np.ndarray, float]:
    """(the first joint's anchor, the height of the bottom of the geometry no joint moves) in
    the model's world frame at ``qpos``: where the arm's base stands. The bottom is the
    anchor's height when nothing is fixed. The table, its walls and the pedestal do not count.
    Mesh geoms count by their vertices (a mesh's box is loose), others by their box."""
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    anchor = data.xanchor[int(np.argmin(model.jnt_qposadr))].copy()
    scenery = {mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) for n in ("table", PEDESTAL)} | {0}
    bottom = float(anchor[2])
    for g in range(model.ngeom):
        body = model.geom_bodyid[g]
        if body in scenery or model.body_weldid[body] != 0:
            continue
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            m = model.geom_dataid[g]
            points = model.mesh_vert[model.mesh_vertadr[m]:model.mesh_vertadr[m] + model.mesh_vertnum[m]]
        else:
            centre, half = model.geom_aabb[g, :3], model.geom_aabb[g, 3:]
            points = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half + centre
        bottom = min(bottom, float(np.min(data.geom_xpos[g][2] + points @ data.geom_xmat[g].reshape(3, 3)[2])))
    return anchor, bottom


CLEARANCE_MIN = 5e-4
"""Tool geometry reaching less than this past the tool point (m) is taken as ending at it."""


def _support(model: mujoco.MjModel, data: mujoco.MjData, g: int, direction: np.ndarray) -> float:
    """How far geom ``g`` reaches along the unit ``direction`` (world) from its centre."""
    u = data.geom_xmat[g].reshape(3, 3).T @ direction  # the direction in the geom's frame
    size = model.geom_size[g]
    kind = model.geom_type[g]
    if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        return float(size[0])
    if kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
        return float(abs(u[2]) * size[1] + size[0])
    if kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        return float(abs(u[2]) * size[1] + size[0] * math.hypot(u[0], u[1]))
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        return float(np.abs(u) @ size)
    if kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
        return float(np.linalg.norm(size * u))
    if kind == mujoco.mjtGeom.mjGEOM_MESH:
        m = model.geom_dataid[g]
        verts = model.mesh_vert[model.mesh_vertadr[m]:model.mesh_vertadr[m] + model.mesh_vertnum[m]]
        return float(np.max(verts @ u))
    centre, half = model.geom_aabb[g, :3], model.geom_aabb[g, 3:]  # anything else: its box
    return float(centre @ u + np.abs(u) @ half)


def tool_reach(model: mujoco.MjModel, qpos: np.ndarray, tip_site: int, direction: np.ndarray | None = None,
               solid: np.ndarray | None = None) -> tuple[float, int]:
    """(how far the tool's own geometry reaches past the tool point along the tool axis, m;
    the geom that reaches farthest, -1 when none reaches past it).

    The tool's geometry is that of the body carrying the tool site and of the bodies that
    hang from it without a joint (held fingers, a pen), counting the geoms that ``solid``
    marks (default: every geom that collides with anything). The axis is the site's z axis,
    or ``direction`` (world) when given."""
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    body = int(model.site_bodyid[tip_site])
    weld = model.body_weldid[body]
    axis = data.site_xmat[tip_site].reshape(3, 3)[:, 2] if direction is None else np.asarray(direction, float)
    axis = axis / np.linalg.norm(axis)
    point = data.site_xpos[tip_site]
    if solid is None:
        solid = (model.geom_contype != 0) | (model.geom_conaffinity != 0)
    best, which = 0.0, -1
    for g in range(model.ngeom):
        b = int(model.geom_bodyid[g])
        if not solid[g] or model.body_weldid[b] != weld:
            continue
        while b > body:  # hangs from the tool's body?
            b = int(model.body_parentid[b])
        if b != body:
            continue
        reach = float((data.geom_xpos[g] - point) @ axis) + _support(model, data, g, axis)
        if reach > best:
            best, which = reach, g
    return (best, which) if best >= CLEARANCE_MIN else (0.0, -1)


def _first_line(err: BaseException) -> str:
    """MuJoCo's whole message on one line (its detail, such as the line of an XML error, comes
    after a line break)."""
    text = " ".join(str(err).split())
    return text or type(err).__name__


@contextmanager
def _mujoco_warnings() -> Iterator[list[str]]:
    """MuJoCo's warnings while the block runs, collected instead of printed and appended to a
    ``MUJOCO_LOG.TXT`` in the working folder."""
    caught: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: caught.append(" ".join(str(message).split())))
    try:
        yield caught
    finally:
        mujoco.set_mju_user_warning(previous)


FINITE_FIELDS = ("qpos0", "body_pos", "body_quat", "body_mass", "body_inertia", "jnt_pos", "jnt_axis", "jnt_range",
                 "geom_pos", "geom_quat", "geom_size", "site_pos", "site_quat", "mesh_vert", "actuator_ctrlrange",
                 "actuator_gainprm", "actuator_biasprm")
"""The compiled model's numbers the scene and the IK use; each must be finite."""


def _load_arm(path: Path) -> tuple[mujoco.MjSpec, mujoco.MjModel]:
    if not path.exists():
        raise ArmModelError(f"cannot read arm MJCF {str(path)!r}: no such file")
    check_input(path, "arm MJCF", ArmModelError)  # MuJoCo reads it: never a FIFO, a device or without bound
    _includes(path, path.parent, set())  # and the files it includes
    with _mujoco_warnings() as caught:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                spec = mujoco.MjSpec.from_file(str(path))
                model = spec.compile()
        except Exception as err:  # noqa: BLE001 - any parse failure is a bad input file
            raise ArmModelError(f"cannot load arm MJCF {str(path)!r}: {_first_line(err)}") from None
    bad = [f for f in FINITE_FIELDS if not np.all(np.isfinite(getattr(model, f)))]
    if bad:
        said = f" (MuJoCo: {'; '.join(caught)})" if caught else ""
        raise ArmModelError(f"arm MJCF {str(path)!r} has a number that is not finite (NaN or infinity) in "
                            f"{bad[0]}{said}")
    return spec, model


def model_files(path: Path) -> list[Path]:
    """Every file MuJoCo reads to build the arm file's model: the file itself, the files it
    ``<include>``s (recursively), and the meshes, textures, height fields and skins its
    parsed spec names, each resolved as MuJoCo resolves it (``meshdir``/``texturedir``
    relative to the model file). Files that are missing are listed too: their absence is
    part of what the model is. Nothing else is read, whatever the folders hold."""
    path = check_input(Path(path), "arm MJCF", ArmModelError)
    files = [path, *_includes(path, path.parent, set())]
    with _mujoco_warnings(), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            spec = mujoco.MjSpec.from_file(str(path))
        except Exception as err:  # noqa: BLE001 - any parse failure is a bad input file
            raise ArmModelError(f"cannot load arm MJCF {str(path)!r}: {_first_line(err)}") from None
    base = Path(spec.modelfiledir or path.parent)
    named = [(spec.meshdir, m.file) for m in spec.meshes] + [(spec.texturedir, t.file) for t in spec.textures]
    named += [(spec.texturedir, f) for t in spec.textures for f in getattr(t, "cubefiles", ()) if f]
    named += [(spec.meshdir, h.file) for h in spec.hfields] + [(spec.meshdir, k.file) for k in spec.skins]
    for folder, name in named:
        if name:
            files.append(base / (folder or "") / name)
    return list(dict.fromkeys(files))  # each file once, in order


def _includes(path: Path, root: Path, seen: set[Path]) -> list[Path]:
    """The files ``path`` includes, recursively (relative names from the main file's folder)."""
    out: list[Path] = []
    try:
        tree = ET.parse(path)
    except (ET.ParseError, OSError):
        return out  # MuJoCo's own parse says what is wrong
    for element in tree.iter("include"):
        name = element.get("file")
        if not name:
            continue
        found = root / name
        if found in seen:
            continue
        seen.add(found)
        out.append(found)
        if os.path.lexists(found):  # MuJoCo reads it too: never a FIFO, a device or without bound
            check_input(found, "file included by the arm MJCF", ArmModelError)
        if found.is_file():
            out.extend(_includes(found, root, seen))
    return out


def _name(model: mujoco.MjModel, obj: mujoco.mjtObj, i: int) -> str:
    return mujoco.mj_id2name(model, obj, i) or ""


def _home_qpos(model: mujoco.MjModel) -> np.ndarray:
    """The ``home`` keyframe's qpos, else qpos0, clipped into the joint ranges."""
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    q = model.key_qpos[key].copy() if key >= 0 else model.qpos0.copy()
    for j in range(model.njnt):
        kind = model.jnt_type[j]
        if model.jnt_limited[j] and (kind == mujoco.mjtJoint.mjJNT_HINGE or kind == mujoco.mjtJoint.mjJNT_SLIDE):
            a = model.jnt_qposadr[j]
            q[a] = np.clip(q[a], *model.jnt_range[j])
    return q


def _tip_body(model: mujoco.MjModel, tool: Tool, where: str) -> int:
    if tool.site is not None:
        sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, tool.site)
        if sid < 0:
            names = [n for n in (_name(model, mujoco.mjtObj.mjOBJ_SITE, i) for i in range(model.nsite)) if n]
            raise ArmModelError(f"arm MJCF {where} has no site {tool.site!r}; its sites: "
                                f"{', '.join(names) if names else 'none (use --tip-body)'}")
        return int(model.site_bodyid[sid])
    bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, tool.body)
    if bid <= 0:
        names = [n for n in (_name(model, mujoco.mjtObj.mjOBJ_BODY, i) for i in range(1, model.nbody)) if n]
        raise ArmModelError(f"arm MJCF {where} has no body {tool.body!r}; its bodies: "
                            f"{', '.join(names) if names else 'none'}")
    return bid


def _chain(model: mujoco.MjModel, tip_body: int, where: str) -> list[int]:
    """Joint ids on the bodies from the tool's body up to the world, in qpos order."""
    bodies = set()
    b = tip_body
    while b > 0:
        bodies.add(b)
        b = int(model.body_parentid[b])
    joints = sorted((j for j in range(model.njnt) if model.jnt_bodyid[j] in bodies),
                    key=lambda j: model.jnt_qposadr[j])
    if not joints:
        raise ArmModelError(f"arm MJCF {where} has no joint between its base and the tool")
    kinds = {int(mujoco.mjtJoint.mjJNT_SLIDE): "slide", int(mujoco.mjtJoint.mjJNT_BALL): "ball"}
    for j in joints:
        if model.jnt_type[j] != mujoco.mjtJoint.mjJNT_HINGE:
            raise ArmModelError(
                f"arm MJCF {where}: joint {_name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or j} on the chain from the "
                f"base to the tool is a {kinds.get(int(model.jnt_type[j]), 'free')} joint; only hinge joints "
                "are supported")
    return joints


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    out = np.empty(4)
    mujoco.mju_mulQuat(out, np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    return out


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    out = np.empty(3)
    mujoco.mju_rotVecQuat(out, np.asarray(v, dtype=float), np.asarray(q, dtype=float))
    return out


def _axis_quat(axis: np.ndarray, angle: float) -> np.ndarray:
    out = np.empty(4)
    mujoco.mju_axisAngle2Quat(out, np.asarray(axis, dtype=float), float(angle))
    return out


def _hold(spec: mujoco.MjSpec, model: mujoco.MjModel, joints: list[int], q: np.ndarray, where: str) -> None:
    """Remove ``joints`` and fix each one's body where its value in ``q`` puts it."""
    by_body: dict[int, list[int]] = {}
    for j in joints:
        by_body.setdefault(int(model.jnt_bodyid[j]), []).append(j)
    for b, js in by_body.items():
        name = _name(model, mujoco.mjtObj.mjOBJ_BODY, b)
        body = spec.body(name) if name else None
        if body is None:
            raise ArmModelError(f"arm MJCF {where}: the body of joint "
                                f"{_name(model, mujoco.mjtObj.mjOBJ_JOINT, js[0]) or js[0]} needs a name")
        pos, quat = model.body_pos[b].copy(), model.body_quat[b].copy()
        for j in sorted(js):
            a = model.jnt_qposadr[j]
            axis, anchor = model.jnt_axis[j], model.jnt_pos[j]
            kind = model.jnt_type[j]
            if kind == mujoco.mjtJoint.mjJNT_SLIDE:
                pos = pos + _rotate(quat, axis * q[a])
                continue
            rot = _axis_quat(axis, q[a]) if kind == mujoco.mjtJoint.mjJNT_HINGE else q[a:a + 4] / np.linalg.norm(q[a:a + 4])
            pos = pos + _rotate(quat, anchor - _rotate(rot, anchor))
            quat = _quat_mul(quat, rot)
        body.pos = pos
        body.quat = quat
        body.alt.type = mujoco.mjtOrientation.mjORIENTATION_QUAT
        for j in js:
            spec.delete(spec.joint(_name(model, mujoco.mjtObj.mjOBJ_JOINT, j)))


def _prune(spec: mujoco.MjSpec, model: mujoco.MjModel, removed: set[int]) -> None:
    """Drop tendons, equalities and sensors that refer to removed joints, and keyframes."""
    gone_tendons = set()
    for t in range(model.ntendon):
        adr, num = model.tendon_adr[t], model.tendon_num[t]
        if any(model.wrap_type[w] == mujoco.mjtWrap.mjWRAP_JOINT and model.wrap_objid[w] in removed
               for w in range(adr, adr + num)):
            gone_tendons.add(t)
    for e in reversed(range(model.neq)):
        kind, o1, o2 = model.eq_type[e], model.eq_obj1id[e], model.eq_obj2id[e]
        if (kind == mujoco.mjtEq.mjEQ_JOINT and (o1 in removed or o2 in removed)) or (
                kind == mujoco.mjtEq.mjEQ_TENDON and (o1 in gone_tendons or o2 in gone_tendons)):
            spec.delete(spec.equalities[e])
    for t in sorted(gone_tendons, reverse=True):
        spec.delete(spec.tendons[t])
    for s in list(spec.sensors):
        spec.delete(s)
    for k in list(spec.keys):
        spec.delete(k)


def _actuators(spec: mujoco.MjSpec, model: mujoco.MjModel, chain: list[int]) -> list[int]:
    """Keep one position servo per chain joint, drop every other actuator; returns the chain
    joints left without one."""
    keep: dict[int, int] = {}
    for a in range(model.nu):
        j = int(model.actuator_trnid[a, 0])
        if (model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT and j in chain and j not in keep
                and model.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_AFFINE
                and abs(model.actuator_gear[a, 0] - 1.0) < 1e-9):
            keep[j] = a
    for a in reversed(range(model.nu)):
        if a not in keep.values():
            spec.delete(spec.actuators[a])
    return [j for j in chain if j not in keep]


@dataclass(frozen=True)
class TorqueMotor:
    """A chain joint the arm file drives with torque motors only (no position servo): the
    scene drops those motors and gives the joint a servo of its own, ``servo_<joint>``."""

    joint: str
    """The joint's name in the arm file."""
    actuators: tuple[str, ...]
    """The file's motors on it (names, or ``#index`` when unnamed)."""
    lower: float
    upper: float
    """The joint torque (N m, or N on a slide) the motors give at most, each way: gear times
    their gain times their control range, within their force range and the joint's
    ``actuatorfrcrange`` (infinite where nothing limits it)."""


def torque_motors(xml_path: Path, chain: tuple[str, ...] | list[str]) -> list[TorqueMotor]:
    """The joints of ``chain`` (names in the arm file) that the file at ``xml_path`` drives only
    with torque motors: actuators on the joint with no bias (``motor``, or ``general`` with no
    ``biastype``) and no dynamics, and no position servo beside them. Empty for a file whose
    chain joints all have a position servo (every built-in arm)."""
    _, model = _load_arm(Path(xml_path))
    out = []
    for joint in chain:
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
        on = [a for a in range(model.nu)
              if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT and int(model.actuator_trnid[a, 0]) == j]
        if j < 0 or not on or any(model.actuator_biastype[a] != mujoco.mjtBias.mjBIAS_NONE
                                  or model.actuator_dyntype[a] != mujoco.mjtDyn.mjDYN_NONE
                                  or model.actuator_gaintype[a] != mujoco.mjtGain.mjGAIN_FIXED for a in on):
            continue
        lower = upper = 0.0
        for a in on:
            gain, gear = float(model.actuator_gainprm[a, 0]), float(model.actuator_gear[a, 0])
            lo, hi = ((float(v) * gain for v in model.actuator_ctrlrange[a]) if model.actuator_ctrllimited[a]
                      else (-math.inf, math.inf))
            lo, hi = min(lo, hi), max(lo, hi)
            if model.actuator_forcelimited[a]:
                lo, hi = max(lo, float(model.actuator_forcerange[a, 0])), min(hi, float(model.actuator_forcerange[a, 1]))
            lo, hi = sorted((gear * lo, gear * hi)) if gear and gain else (0.0, 0.0)
            lower, upper = lower + lo, upper + hi
        if model.jnt_actfrclimited[j]:
            lower, upper = max(lower, float(model.jnt_actfrcrange[j, 0])), min(upper, float(model.jnt_actfrcrange[j, 1]))
        names = tuple(_name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, a) or f"#{a}" for a in on)
        out.append(TorqueMotor(joint, names, lower, upper))
    return out


STYLUS = "stylus_held"
"""Name of the geom of a held :class:`~armtransfer.ik.tool.Stylus` (the pen)."""


def _tool_site(spec: mujoco.MjSpec, model: mujoco.MjModel, tool: Tool, tip_body: int) -> str:
    """The site the scene uses as the tool tip (added when the tool has an offset, is a body or
    holds a stylus; a held stylus is a capsule from the tool point along the tool axis, and the
    site is at its end)."""
    if tool.site is not None and not tool.has_offset and tool.held is None:
        return tool.site
    if tool.site is not None:
        sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, tool.site)
        frame_pos, frame_quat = model.site_pos[sid].copy(), model.site_quat[sid].copy()
    else:
        frame_pos, frame_quat = np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])
    offset = np.array(tool.offset)
    quat = frame_quat
    if tool.has_offset:  # the tool's z axis along the offset, from the frame to the tip
        turn = np.empty(4)
        mujoco.mju_quatZ2Vec(turn, offset / np.linalg.norm(offset))
        quat = _quat_mul(frame_quat, turn)
    name = TOOL_SITE
    existing = {_name(model, mujoco.mjtObj.mjOBJ_SITE, i) for i in range(model.nsite)}
    while name in existing:
        name += "_"
    body_name = _name(model, mujoco.mjtObj.mjOBJ_BODY, tip_body)
    body = spec.body(body_name) if body_name else None
    if body is None:
        raise ArmModelError("the tool's body needs a name in the arm MJCF")
    point = frame_pos + _rotate(frame_quat, offset)
    if tool.held is not None:
        end = point + _rotate(quat, np.array([0.0, 0.0, tool.held.length]))
        pen = STYLUS
        geoms = {_name(model, mujoco.mjtObj.mjOBJ_GEOM, i) for i in range(model.ngeom)}
        while pen in geoms:
            pen += "_"
        body.add_geom(name=pen, type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[tool.held.radius, 0.0, 0.0],
                      fromto=[*map(float, point), *map(float, end)], rgba=[0.15, 0.15, 0.18, 1.0],
                      contype=1, conaffinity=1, group=0)
        point = end
    body.add_site(name=name, pos=point, quat=quat, size=[0.004, 0, 0],
                  rgba=[0.9, 0.2, 0.2, 1.0], group=4)
    return name


def _copy_options(src: mujoco.MjSpec, dst: mujoco.MjSpec) -> None:
    """The scene's physics options win: copy them onto the arm so attaching raises no conflict."""
    for attr in dir(src.option):
        if attr.startswith("_"):
            continue
        try:
            setattr(dst.option, attr, getattr(src.option, attr))
        except (AttributeError, TypeError):
            pass


def _pedestal(scene_spec: mujoco.MjSpec, model: mujoco.MjModel, q: np.ndarray, mount_pos, mount_quat,
              half: float) -> None:
    """Draw a column from the tabletop up to a base mounted above it, so that the arm does not
    float in a video. Only a base over the table gets one; it collides with nothing."""
    anchor, bottom = base_footing(model, q)
    x, y = np.asarray(mount_pos[:2], dtype=float) + _rotate(mount_quat, anchor)[:2]
    lift = float(mount_pos[2]) + bottom
    if lift <= 1e-4 or abs(x) > half or abs(y) > half:
        return
    column = scene_spec.worldbody.add_body(name=PEDESTAL, pos=[float(x), float(y), lift / 2])
    column.add_geom(name=PEDESTAL, type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[PEDESTAL_RADIUS, lift / 2, 0.0],
                    material="wall_mat", contype=0, conaffinity=0)


def build_scene(xml_path: Path, tool: Tool | str = "tip", mount_pos=(0.0, 0.0, 0.0),
                mount_yaw: float = 0.0, cell: float = DEFAULT_CELL, *, layout: Layout,
                wall_height: float = WALL_HEIGHT) -> ArmScene:
    """Attach the arm at ``xml_path`` to the workspace (see the module docstring)."""
    tool = Tool(site=tool) if isinstance(tool, str) else tool
    path = Path(xml_path)
    where = repr(str(path))
    spec, model = _load_arm(path)
    if any(model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE for j in range(model.njnt)):
        raise ArmModelError(f"arm MJCF {where} has a free joint; a fixed-base serial arm is needed")
    tip_body = _tip_body(model, tool, where)
    chain = _chain(model, tip_body, where)
    q_all = _home_qpos(model)
    off = [j for j in range(model.njnt) if j not in chain]
    joint_name = lambda j: _name(model, mujoco.mjtObj.mjOBJ_JOINT, j)  # noqa: E731
    for j in chain:
        if not joint_name(j):
            raise ArmModelError(f"arm MJCF {where}: every joint on the chain from the base to the tool needs a name")
    held = tuple((joint_name(j) or f"#{j}", float(q_all[model.jnt_qposadr[j]])) for j in off
                 if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE or model.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE)
    tip_name = _tool_site(spec, model, tool, tip_body)
    unservoed = _actuators(spec, model, chain)
    _prune(spec, model, set(off))
    _hold(spec, model, off, q_all, where)
    arm_name = spec.modelname or path.stem
    scene_spec = build_workspace(layout, cell, wall_height)
    _copy_options(scene_spec, spec)
    mount_quat = [math.cos(mount_yaw / 2), 0.0, 0.0, math.sin(mount_yaw / 2)]
    _pedestal(scene_spec, model, q_all, mount_pos, mount_quat, layout.width * cell / 2)
    frame = scene_spec.worldbody.add_frame(pos=[float(v) for v in mount_pos], quat=mount_quat)
    try:
        with warnings.catch_warnings(), _mujoco_warnings():
            warnings.simplefilter("ignore")
            scene_spec.attach(spec, prefix=PREFIX, frame=frame)
            for j in unservoed:
                lo, hi = model.jnt_range[j]
                scene_spec.add_actuator(
                    name=f"{PREFIX}servo_{joint_name(j)}", target=PREFIX + joint_name(j),
                    trntype=mujoco.mjtTrn.mjTRN_JOINT, gainprm=[SERVO_KP] + [0.0] * 9,
                    biastype=mujoco.mjtBias.mjBIAS_AFFINE, biasprm=[0.0, -SERVO_KP, -0.1 * SERVO_KP] + [0.0] * 7,
                    ctrllimited=bool(model.jnt_limited[j]), ctrlrange=[lo, hi])
            scene = scene_spec.compile()
            xml = scene_spec.to_xml()
    except Exception as err:  # noqa: BLE001
        raise ArmModelError(f"arm MJCF {where} does not compile in the scene: {_first_line(err)}") from None
    home = q_all[model.jnt_qposadr[chain]]
    if scene.nq != len(chain):
        raise ArmModelError(f"arm MJCF {where}: the scene has {scene.nq} positions for {len(chain)} chain joints")
    table_body = mujoco.mj_name2id(scene, mujoco.mjtObj.mjOBJ_BODY, "table")
    env = scene.geom_bodyid == table_body
    arm_geoms = (scene.geom_bodyid != table_body) & (scene.body_weldid[scene.geom_bodyid] != 0)
    lower = np.full(scene.nq, -np.inf)
    upper = np.full(scene.nq, np.inf)
    for j in range(scene.njnt):
        adr = scene.jnt_qposadr[j]
        if scene.jnt_limited[j]:
            lower[adr], upper[adr] = scene.jnt_range[j]
    data = mujoco.MjData(scene)
    data.qpos[:] = home
    mujoco.mj_kinematics(scene, data)
    planar = bool(np.all(np.abs(np.abs(data.xaxis[:, 2]) - 1.0) < 1e-6))
    if planar and tool.held is not None:
        raise ArmModelError(f"arm MJCF {where} moves in a plane at a fixed height, so a held {tool.held.spec()} would "
                            "put its tip off the table; a held tool needs a spatial arm (its tool kept pointing "
                            "down): for a planar arm's own pen, give --cell-size for wider doors")
    tip_id = mujoco.mj_name2id(scene, mujoco.mjtObj.mjOBJ_SITE, PREFIX + tip_name)
    table_geoms = np.flatnonzero(env)
    hits_table = np.zeros(scene.ngeom, dtype=bool)
    for t in table_geoms:
        hits_table |= ((scene.geom_contype & scene.geom_conaffinity[t]) | (scene.geom_conaffinity & scene.geom_contype[t])) != 0
    clearance, geom = tool_reach(scene, home, tip_id, np.array([0.0, 0.0, -1.0]) if planar else None,
                                 hits_table & arm_geoms)
    return ArmScene(model=scene, xml=xml, tip=PREFIX + tip_name, home=home, lower=lower,
                    upper=upper, env_geoms=env, arm_geoms=arm_geoms, cell=cell, layout=layout,
                    planar=planar, name=arm_name, chain=tuple(joint_name(j) for j in chain), held=held,
                    tool=tool, clearance=round(clearance, 6),
                    clearance_geom=(_name(scene, mujoco.mjtObj.mjOBJ_GEOM, geom).removeprefix(PREFIX) or
                                    f"a geom of body {_name(scene, mujoco.mjtObj.mjOBJ_BODY, int(scene.geom_bodyid[geom])).removeprefix(PREFIX)}")
                    if geom >= 0 else "")


class ContactChecker:
    """Does the arm touch the table, a wall or itself at configuration q? (MuJoCo collision.)

    A self-contact is one between two of the arm's geoms, at least one of them moved by a
    joint, that MuJoCo reports (it already skips a body and its parent, and the file's
    ``<exclude>`` pairs). Pairs already in contact at the home configuration are the file's
    own design (a wrist flange seated in its link) and are allowed."""

    def __init__(self, scene: ArmScene) -> None:
        self.scene = scene
        self.model = scene.model
        self.data = mujoco.MjData(scene.model)
        self._env = scene.env_geoms
        self._moving = scene.arm_geoms
        self._arm = ~scene.env_geoms & (scene.model.geom_bodyid != 0)
        self._walls = np.array([(mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_GEOM, g) or "").startswith("wall_")
                                for g in range(self.model.ngeom)], dtype=bool) & scene.env_geoms
        self._tip = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)
        self._allowed = np.zeros((self.model.ngeom, self.model.ngeom), dtype=bool)
        g1, g2 = self._self_contacts(scene.home)
        self._allowed[g1, g2] = self._allowed[g2, g1] = True
        m = self.model
        arm = np.flatnonzero(self._arm)
        ct, ca = m.geom_contype[arm], m.geom_conaffinity[arm]
        pairs = ((ct[:, None] & ca[None, :]) | (ca[:, None] & ct[None, :])) != 0
        pairs &= m.geom_bodyid[arm][:, None] != m.geom_bodyid[arm][None, :]
        pairs &= self._moving[arm][:, None] | self._moving[arm][None, :]
        self.can_self_collide = bool(pairs.any())
        """Whether any two of the arm's geoms on different bodies, one of them moving, may
        collide by their contype/conaffinity (the built-in arms' may not)."""

    @property
    def walls(self) -> np.ndarray:
        """Boolean over geoms: the workspace's walls."""
        return self._walls

    def contacts(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every contact MuJoCo finds at q, as two arrays of geom ids (kinematics and collision
        are run on :attr:`data`)."""
        return self._contacts(q)

    def _contacts(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d = self.data
        d.qpos[:] = q
        mujoco.mj_kinematics(self.model, d)
        mujoco.mj_collision(self.model, d)
        n = d.ncon
        return d.contact.geom1[:n], d.contact.geom2[:n]

    def _mine(self, g1: np.ndarray, g2: np.ndarray) -> np.ndarray:
        """Which contacts are between two arm geoms, one of them moving."""
        return self._arm[g1] & self._arm[g2] & (self._moving[g1] | self._moving[g2])

    def _own(self, g1: np.ndarray, g2: np.ndarray) -> np.ndarray:
        """Which contacts are self-contacts that count (not there at home)."""
        return self._mine(g1, g2) & ~self._allowed[g1, g2]

    def _self_contacts(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        g1, g2 = self._contacts(q)
        mine = self._mine(g1, g2)
        return g1[mine], g2[mine]

    def touches(self, q: np.ndarray) -> bool:
        return self._counts(*self._contacts(q))

    def touches_now(self) -> bool:
        """``touches`` at the configuration whose kinematics and collision detection were last
        run on :attr:`data` (by the caller), without running them again."""
        n = self.data.ncon
        return self._counts(self.data.contact.geom1[:n], self.data.contact.geom2[:n])

    def _counts(self, g1: np.ndarray, g2: np.ndarray) -> bool:
        """Whether any of these contacts is one ``touches`` counts."""
        if len(g1) == 0:
            return False
        env = (self._env[g1] & self._moving[g2]) | (self._env[g2] & self._moving[g1])
        return bool(np.any(env | self._own(g1, g2)))

    def self_contacts(self, q: np.ndarray) -> list[tuple[str, str]]:
        """The arm's bodies in contact with each other at q (pairs allowed at home left out)."""
        g1, g2 = self._contacts(q)
        own = self._own(g1, g2)
        names = set()
        for a, b in zip(g1[own], g2[own]):
            bodies = (int(self.model.geom_bodyid[g]) for g in (a, b))
            pair = sorted(_name(self.model, mujoco.mjtObj.mjOBJ_BODY, i) or f"body {i}" for i in bodies)
            names.add((pair[0], pair[1]))
        return sorted(names)

    def contact_names(self, q: np.ndarray) -> list[str]:
        """The contacts that ``touches`` counts at q, named: ``"left_finger with the table"``,
        ``"wrist_3_link with wall wall_2"``, ``"link1 with link4"`` (arm bodies by name)."""
        g1, g2 = self._contacts(q)
        env = (self._env[g1] & self._moving[g2]) | (self._env[g2] & self._moving[g1])
        counted = env | self._own(g1, g2)
        out: list[str] = []
        for a, b in zip(g1[counted], g2[counted]):
            if self._env[a]:
                a, b = b, a
            text = f"{self._what(int(a))} with {self._what(int(b))}"
            if text not in out:
                out.append(text)
        return out

    def _what(self, g: int) -> str:
        m = self.model
        if self._env[g]:
            name = _name(m, mujoco.mjtObj.mjOBJ_GEOM, g)
            return f"wall {name}" if self._walls[g] else "the table"
        body = int(m.geom_bodyid[g])
        return (_name(m, mujoco.mjtObj.mjOBJ_BODY, body) or f"body {body}").removeprefix(PREFIX)

    def base_on_wall(self) -> bool:
        """Does the arm's fixed base (collision geoms that no joint moves) stand in a wall?

        MuJoCo never collides two bodies fixed to the world, so this asks for distances."""
        m, d = self.model, self.data
        d.qpos[:] = self.scene.home
        mujoco.mj_kinematics(m, d)
        solid = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
        static = np.flatnonzero(solid & ~self._moving & ~self._env & (m.geom_bodyid != 0))
        fromto = np.zeros(6)
        return any(mujoco.mj_geomDistance(m, d, int(a), int(w), 0.01, fromto) < 0.0
                   for a in static for w in np.flatnonzero(self._walls))

    def tip(self, q: np.ndarray) -> np.ndarray:
        """The tip position after the last ``touches`` call at q (or computed now)."""
        d = self.data
        d.qpos[:] = q
        mujoco.mj_kinematics(self.model, d)
        return d.site_xpos[self._tip].copy()

    def touches_and_tip(self, q: np.ndarray) -> tuple[bool, np.ndarray]:
        hit = self.touches(q)
        return hit, self.data.site_xpos[self._tip].copy()

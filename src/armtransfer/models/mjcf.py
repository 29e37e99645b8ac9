"""MJCF text of the project's arms, from their dimensions: planar SCARA-like arms, and spatial
arms from body frames (Denavit-Hartenberg tables turned into MuJoCo bodies).

The built-in arms (``scripts/make_arm_models.py`` writes src/armtransfer/models/<arm>/<arm>.xml) and the
generated ones (``armtransfer.models.generate``) are written by the same functions, so they
follow one contract: a ``tip`` site, a ``home`` keyframe, hinge joints ``joint1..N`` and a
position actuator per joint named like it.

Standard DH (UR5e): T_i = Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i), so the child body sits at
pos (a_i, 0, d_i) with orientation Rx(alpha_i) and rotates about its own z.
Modified DH (Panda): T_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(q_i) Tz(d_i), so body i sits at
(a_{i-1}, 0, 0) + Rx(alpha_{i-1}) (0, 0, d_i) with orientation Rx(alpha_{i-1}).
"""

from __future__ import annotations

import math

import numpy as np

TIP_CLEARANCE = 0.004  # the stylus tip hovers this far above the tabletop (m)


def _f(v: float) -> str:
    s = f"{v:.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _vec(v) -> str:
    return " ".join(_f(float(x)) for x in v)


def _quat_rx(alpha: float) -> str:
    return _vec((math.cos(alpha / 2), math.sin(alpha / 2), 0.0, 0.0))


HEADER = """<mujoco model="{name}">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="0.002" integrator="implicitfast"/>
  <default>
    <default class="{name}">
      <joint damping="{damping}" armature="{armature}"/>
      <geom contype="1" conaffinity="0" density="{density}" rgba="{rgba}"/>
      <position kp="{kp}" kv="{kv}"/>
      <site size="0.004" rgba="1 0.2 0.2 1"/>
    </default>
  </default>
"""


def planar_arm(name: str, lengths: list[float], limits: list[float], home: list[float],
               height: float = 0.12, drop: float = 0.025) -> str:
    """A SCARA-like planar arm: vertical joint axes, links stacked ``drop`` apart from
    ``height`` above the tabletop down, and a vertical stylus from the last link to the table."""
    radius = 0.012
    out = [HEADER.format(name=name, damping=0.5, armature=0.01, density=800,
                         rgba="0.3 0.45 0.7 1", kp=20, kv=0.5)]
    out.append("  <worldbody>\n")
    out.append(f'    <body name="base" childclass="{name}">\n')
    out.append(f'      <geom name="base_housing" type="cylinder" size="0.03 0.02" '
               f'pos="0 0 {_f(height + 0.035)}"/>\n')
    indent = "      "
    z = height
    for i, length in enumerate(lengths, start=1):
        pos = "0 0 " + _f(height) if i == 1 else f"{_f(lengths[i - 2])} 0 {_f(-drop)}"
        out.append(f'{indent}<body name="link{i}" pos="{pos}">\n')
        lim = limits[i - 1]
        out.append(f'{indent}  <joint name="joint{i}" type="hinge" axis="0 0 1" '
                   f'range="{_f(-lim)} {_f(lim)}"/>\n')
        out.append(f'{indent}  <geom name="link{i}_bar" type="capsule" size="{radius}" '
                   f'fromto="0 0 0 {_f(length)} 0 0"/>\n')
        if i > 1:
            out.append(f'{indent}  <geom name="joint{i}_hub" type="cylinder" '
                       f'size="{radius * 1.4} {_f(drop / 2 + radius)}" pos="0 0 {_f(drop / 2)}"/>\n')
        indent += "  "
        if i > 1:
            z -= drop
    stylus = z - TIP_CLEARANCE
    last = lengths[-1]
    out.append(f'{indent}<geom name="stylus" type="cylinder" size="0.0015" '
               f'fromto="{_f(last)} 0 0 {_f(last)} 0 {_f(-stylus)}"/>\n')
    out.append(f'{indent}<site name="tip" pos="{_f(last)} 0 {_f(-stylus)}"/>\n')
    for _ in lengths:
        indent = indent[:-2]
        out.append(f"{indent}</body>\n")
    out.append("    </body>\n  </worldbody>\n")
    out.append(_actuators(name, len(lengths), limits))
    out.append(f'  <keyframe>\n    <key name="home" qpos="{_vec(home)}" ctrl="{_vec(home)}"/>\n'
               "  </keyframe>\n</mujoco>\n")
    return "".join(out)


def _actuators(name: str, n: int, limits, lows=None) -> str:
    lines = ["  <actuator>\n"]
    for i in range(1, n + 1):
        lo = -limits[i - 1] if lows is None else lows[i - 1]
        hi = limits[i - 1]
        lines.append(f'    <position name="joint{i}" class="{name}" joint="joint{i}" '
                     f'ctrlrange="{_f(lo)} {_f(hi)}"/>\n')
    lines.append("  </actuator>\n")
    return "".join(lines)


def spatial_arm(name: str, frames: list[tuple[tuple, float]], lows, highs, radii, tool: float,
                flange: float, home, kp: float, rgba: str) -> str:
    """A serial arm from body frames: frames[i] = (pos of body i+1 in body i, alpha)."""
    out = [HEADER.format(name=name, damping=2.0, armature=0.05, density=1200, rgba=rgba,
                         kp=kp, kv=kp / 20)]
    out.append("  <worldbody>\n")
    out.append(f'    <body name="base" childclass="{name}">\n')
    out.append(f'      <geom name="pedestal" type="cylinder" size="{_f(radii[0] * 1.3)} 0.02" '
               'pos="0 0 0.02"/>\n')
    indent = "      "
    n = len(frames)
    for i in range(1, n + 1):
        pos, alpha = frames[i - 1]
        out.append(f'{indent}<body name="link{i}" pos="{_vec(pos)}" quat="{_quat_rx(alpha)}">\n')
        out.append(f'{indent}  <joint name="joint{i}" type="hinge" axis="0 0 1" '
                   f'range="{_f(lows[i - 1])} {_f(highs[i - 1])}"/>\n')
        out.append(f'{indent}  <geom name="link{i}_hub" type="cylinder" size="{_f(radii[i - 1])} '
                   f'{_f(radii[i - 1])}"/>\n')
        child = np.array(frames[i][0]) if i < n else np.array((0.0, 0.0, flange))
        if np.linalg.norm(child) > 1e-9:
            out.append(f'{indent}  <geom name="link{i}_bar" type="capsule" '
                       f'size="{_f(radii[i - 1] * 0.8)}" fromto="0 0 0 {_vec(child)}"/>\n')
        indent += "  "
    out.append(f'{indent}<geom name="stylus" type="cylinder" size="0.003" '
               f'fromto="0 0 {_f(flange)} 0 0 {_f(flange + tool)}"/>\n')
    out.append(f'{indent}<site name="tip" pos="0 0 {_f(flange + tool)}"/>\n')
    for _ in range(n):
        indent = indent[:-2]
        out.append(f"{indent}</body>\n")
    out.append("    </body>\n  </worldbody>\n")
    lines = ["  <actuator>\n"]
    for i in range(1, n + 1):
        lines.append(f'    <position name="joint{i}" class="{name}" joint="joint{i}" '
                     f'ctrlrange="{_f(lows[i - 1])} {_f(highs[i - 1])}"/>\n')
    lines.append("  </actuator>\n")
    out.append("".join(lines))
    out.append(f'  <keyframe>\n    <key name="home" qpos="{_vec(home)}" ctrl="{_vec(home)}"/>\n'
               "  </keyframe>\n</mujoco>\n")
    return "".join(out)


# Standard DH of the UR5e as published by Universal Robots (m, rad).
UR5E_DH = dict(d=(0.1625, 0, 0, 0.1333, 0.0997, 0.0996), a=(0, -0.425, -0.3922, 0, 0, 0),
               alpha=(math.pi / 2, 0, 0, math.pi / 2, -math.pi / 2, 0))
# Modified DH of the Franka Panda as published by Franka Emika (m, rad); flange 0.107.
PANDA_DH = dict(a=(0, 0, 0, 0.0825, -0.0825, 0, 0.088), d=(0.333, 0, 0.316, 0, 0.384, 0, 0),
                alpha=(0, -math.pi / 2, math.pi / 2, math.pi / 2, -math.pi / 2, math.pi / 2,
                       math.pi / 2))
PANDA_FLANGE = 0.107


def standard_dh_frames(d, a, alpha) -> list[tuple[tuple, float]]:
    """Body frames of a standard-DH arm: body 1 on the base, body i+1 in body i at
    (a_i, 0, d_i) rotated Rx(alpha_i); the flange is (0, 0, d_n) in the last body."""
    frames = [((0.0, 0.0, 0.0), 0.0)]
    for i in range(len(d) - 1):
        frames.append(((a[i], 0.0, d[i]), alpha[i]))
    return frames


def modified_dh_frames(a, d, alpha) -> list[tuple[tuple, float]]:
    """Body frames of a modified-DH arm: body i at (a_{i-1}, 0, 0) + Rx(alpha_{i-1}) (0, 0, d_i)."""
    return [((a[i], -math.sin(alpha[i]) * d[i], math.cos(alpha[i]) * d[i]), alpha[i]) for i in range(len(a))]


def ur5e_frames():
    return standard_dh_frames(UR5E_DH["d"], UR5E_DH["a"], UR5E_DH["alpha"])


def panda_frames():
    return modified_dh_frames(PANDA_DH["a"], PANDA_DH["d"], PANDA_DH["alpha"])


UR5E_LIMITS = ([-2 * math.pi, -math.pi, -math.pi, -2 * math.pi, -2 * math.pi, -2 * math.pi],
               [2 * math.pi, math.pi, math.pi, 2 * math.pi, 2 * math.pi, 2 * math.pi])
PANDA_LIMITS = ([-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973],
                [2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973])


BUILT_IN = {
    "planar2": lambda: planar_arm("planar2", [0.20, 0.20], [3.1, 3.0], [0.0, 1.5]),
    "planar3": lambda: planar_arm("planar3", [0.16, 0.13, 0.11], [3.1, 2.6, 2.6],
                                  [0.0, 1.2, 1.2]),
    "planar4": lambda: planar_arm("planar4", [0.13, 0.11, 0.09, 0.07], [3.1, 2.4, 2.4, 1.6],
                                  [0.0, 1.0, 1.0, 0.5]),
    "ur5e_like": lambda: spatial_arm(
        "ur5e_like", ur5e_frames(),
        lows=UR5E_LIMITS[0], highs=UR5E_LIMITS[1],
        radii=[0.06, 0.055, 0.045, 0.04, 0.04, 0.035], tool=0.12, flange=UR5E_DH["d"][5],
        home=HOMES["ur5e_like"], kp=400, rgba="0.55 0.6 0.65 1"),
    "panda_like": lambda: spatial_arm(
        "panda_like", panda_frames(),
        lows=PANDA_LIMITS[0], highs=PANDA_LIMITS[1],
        radii=[0.06, 0.06, 0.055, 0.055, 0.05, 0.045, 0.04], tool=0.10, flange=PANDA_FLANGE,
        home=HOMES["panda_like"], kp=400, rgba="0.9 0.9 0.92 1"),
}

"""The built-in arms' MJCF writers (``scripts/make_arm_models.py`` writes them to src/armtransfer/models/)."""

# Home configurations of the spatial arms: the tip over the table centre, pointing down,
# for the mounting in src/armtransfer/models/__init__.py (found with mink IK and rounded).
HOMES: dict[str, list[float]] = {
    "ur5e_like": [-0.323, -1.293, 2.381, -2.66, -1.571, 0.148],
    "panda_like": [0.023, 0.417, -0.01, -2.656, 0.057, 3.073, 0.874],
}

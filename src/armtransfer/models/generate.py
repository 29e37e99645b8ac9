"""Arm families with parameters drawn within ranges: planar N-link SCARA-like arms, and
spatial arms from Denavit-Hartenberg ranges around real 6- and 7-joint arms.

A draw is pure text: the MJCF (written by ``armtransfer.models.mjcf``, as the built-in
arms are), its parameters, where to mount it and whether its tool points down. Whether a
draw meets the arm contract and reaches the Table I cells is decided one layer up
(``armtransfer.tasks.generated``), which rejects a draw and draws again from the same
generator. Every number comes from the ``numpy.random.Generator`` passed in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from armtransfer.errors import UnknownArmError
from armtransfer.models import PLANAR_MOUNT
from armtransfer.models import mjcf

FAMILIES = {
    "planar": tuple(range(2, 8)),
    "spatial6": (6,),
    "spatial7": (7,),
}
"""Family -> the joint counts it has."""

PLANAR_REACH = (0.33, 0.42)
"""Total link length (m) of a planar arm, mounted over cell (-3, 3): Table I's farthest cells
are 0.28 m from there."""
PLANAR_LIMIT = {2: (2.85, 3.05), 3: (2.4, 3.0)}
"""Joint limit (+-rad) of a planar arm's joints after the first (the first turns +-3.1), by
joint count: a 2-link arm must fold almost flat to reach near its base; more links share it."""
PLANAR_LIMIT_MANY = (2.2, 3.0)
LOWEST_LINK = 0.06
"""Height (m) of a generated planar arm's lowest link above the tabletop."""
DH_SPREAD = 0.12
"""Spatial arms: every non-zero DH length is the real arm's times U(1 - spread, 1 + spread)."""


@dataclass(frozen=True)
class ArmDraw:
    name: str
    family: str
    dof: int
    xml: str
    params: dict
    """The drawn parameters (lengths in m, limits in rad)."""
    mount_pos: tuple[float, float, float]
    mount_yaw: float
    tip_down: bool
    kind: str
    """``planar`` or ``spatial``: which action models it has (joint and cartesian, or cartesian)."""
    joint_step: float | None = None
    """For planar arms: the lattice step of the ``joint`` action model."""
    extra: dict = field(default_factory=dict)


def check_family(family: str, dof: int) -> None:
    if family not in FAMILIES:
        raise UnknownArmError(f"unknown arm family {family!r}; valid families: {', '.join(FAMILIES)}")
    if dof not in FAMILIES[family]:
        valid = ", ".join(map(str, FAMILIES[family]))
        raise UnknownArmError(f"family {family!r} has no {dof}-joint arms; valid joint counts: {valid}")


def draw_arm(family: str, dof: int, rng: np.random.Generator, name: str) -> ArmDraw:
    """One arm of ``family`` with ``dof`` joints, its parameters drawn from ``rng``."""
    check_family(family, dof)
    if family == "planar":
        return _planar(dof, rng, name)
    return _spatial(family, rng, name)


def _r(x: float) -> float:
    """Drawn lengths and angles are kept to 0.1 mm / 1 mrad, so the MJCF text is short."""
    return round(float(x), 4)


def _planar(n: int, rng: np.random.Generator, name: str) -> ArmDraw:
    reach = rng.uniform(*PLANAR_REACH)
    # the first link about as long as the rest together, so the arm can fold near its base
    first = reach * rng.uniform(0.46, 0.54)
    rest = rng.dirichlet(np.full(n - 1, 3.0)) * (reach - first) if n > 1 else np.zeros(0)
    lengths = [_r(first), *(_r(max(v, 0.02)) for v in sorted(rest, reverse=True))]
    limit = PLANAR_LIMIT.get(n, PLANAR_LIMIT_MANY)
    limits = [3.1, *(_r(rng.uniform(*limit)) for _ in range(n - 1))]
    home = [0.0, *(_r(min(1.0, 0.8 * lim)) for lim in limits[1:])]
    # links stacked so the lowest (its hub reaches 2.4 cm below it) clears the 2 cm walls
    drop = 0.025 if n <= 4 else 0.015
    height = _r(max(0.12, LOWEST_LINK + drop * (n - 1)))
    xml = mjcf.planar_arm(name, lengths, limits, home, height=height, drop=drop)
    step = _r(min(0.25, 0.05 * 2 ** (n - 2)))
    params = {"lengths": lengths, "limits": limits, "home": home, "height": height, "drop": drop}
    return ArmDraw(name, "planar", n, xml, params, PLANAR_MOUNT, 0.0, False, "planar", joint_step=step)


def _scaled(values, rng: np.random.Generator) -> list[float]:
    return [_r(v * rng.uniform(1 - DH_SPREAD, 1 + DH_SPREAD)) if v else 0.0 for v in values]


def _spatial(family: str, rng: np.random.Generator, name: str) -> ArmDraw:
    if family == "spatial6":
        d = _scaled(mjcf.UR5E_DH["d"], rng)
        a = _scaled(mjcf.UR5E_DH["a"], rng)
        alpha = list(mjcf.UR5E_DH["alpha"])
        frames = mjcf.standard_dh_frames(d, a, alpha)
        lows, highs = mjcf.UR5E_LIMITS
        home = mjcf.HOMES["ur5e_like"]
        flange, tool = d[-1], 0.12
        radii = [0.06, 0.055, 0.045, 0.04, 0.04, 0.035]
        mount, yaw, convention = (0.0, -0.42, 0.0), -math.pi / 2, "standard"
        rgba = "0.55 0.6 0.65 1"
    else:
        a = _scaled(mjcf.PANDA_DH["a"], rng)
        d = _scaled(mjcf.PANDA_DH["d"], rng)
        alpha = list(mjcf.PANDA_DH["alpha"])
        frames = mjcf.modified_dh_frames(a, d, alpha)
        lows, highs = mjcf.PANDA_LIMITS
        home = mjcf.HOMES["panda_like"]
        flange, tool = _r(mjcf.PANDA_FLANGE * rng.uniform(1 - DH_SPREAD, 1 + DH_SPREAD)), 0.10
        radii = [0.06, 0.06, 0.055, 0.055, 0.05, 0.045, 0.04]
        mount, yaw, convention = (0.0, -0.40, 0.0), math.pi / 2, "modified"
        rgba = "0.9 0.9 0.92 1"
    xml = mjcf.spatial_arm(name, frames, lows=lows, highs=highs, radii=radii, tool=tool, flange=flange,
                           home=home, kp=400, rgba=rgba)
    params = {"dh": convention, "d": d, "a": a, "alpha": [_r(x) for x in alpha], "flange": flange, "tool": tool}
    return ArmDraw(name, family, len(frames), xml, params, mount, yaw, True, "spatial")


def with_home(draw: ArmDraw, home: list[float]) -> ArmDraw:
    """The same arm with another ``home`` keyframe (the generator solves one by IK)."""
    text = " ".join(mjcf._f(float(v)) for v in home)
    start = draw.xml.index('<key name="home" qpos="')
    end = draw.xml.index("/>", start)
    key = f'<key name="home" qpos="{text}" ctrl="{text}"'
    return ArmDraw(draw.name, draw.family, draw.dof, draw.xml[:start] + key + draw.xml[end:],
                   {**draw.params, "home": [float(v) for v in home]}, draw.mount_pos, draw.mount_yaw,
                   draw.tip_down, draw.kind, draw.joint_step, draw.extra)


def planar_tip_cells(draw: ArmDraw, cell: float, samples: int = 20000) -> set[tuple[int, int]]:
    """The cells a planar draw's tip can be over, estimated from ``samples`` configurations
    spread evenly within its joint limits (a fixed quasi-random grid, so it is the same every
    time): cheap enough to reject a draw before compiling it."""
    lengths = np.asarray(draw.params["lengths"])
    limits = np.asarray(draw.params["limits"])
    rng = np.random.default_rng(0)
    q = rng.uniform(-1.0, 1.0, size=(samples, len(lengths))) * limits
    angles = np.cumsum(q, axis=1)
    xy = np.stack([(lengths * np.cos(angles)).sum(1), (lengths * np.sin(angles)).sum(1)], axis=1)
    xy += np.asarray(draw.mount_pos[:2])
    return set(map(tuple, np.rint(xy / cell).astype(int).tolist()))

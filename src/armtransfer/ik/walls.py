"""Why an arm misses the cells by the walls: the geometry that meets them, measured, and the remedy.

A tool wider than a door at the walls' height cannot pass the doors, nor reach the cells along
the walls: a gripper whose fingertips ride just above the table, or a thick pen. When an arm
reaches too few of the free cells, :func:`wall_cause` places the tool point over unreached free
cells next to the walls (doors first) with IK, keeps the tries where the tool got there but the
arm touches a wall, and names the arm geometry that met the walls most often, its width across
at the walls' height against the door's, and what to change:

- an arm whose tool is kept pointing down: a held pen (``--tool stylus``), which rides the hand
  above the walls, or a longer ``--tip-offset``;
- a planar arm, whose height is fixed: wider cells (``--cell-size``), so that the doors are
  wider than the tool.
"""

from __future__ import annotations

import math
from collections import Counter

import mujoco
import numpy as np

from armtransfer.ik.scene import PREFIX, ArmScene, ContactChecker, _name
from armtransfer.ik.solve import TipIK
from armtransfer.ik.tool import STYLUS_LENGTH
from armtransfer.ik.workspace import WALL_HEIGHT

REACH_OK = 0.8
"""An arm that reaches less than this share of the free cells is asked why."""
TRIES = 12
"""Unreached cells by the walls tried (doors first)."""
RESTARTS = 2
"""Random starting configurations per cell, after home."""
MARGIN = 0.002
"""Room (m) the suggested cell size leaves either side of the tool in a door."""
LIFT_MARGIN = 0.005
"""Height (m) a lifted tool's geometry is to clear the wall tops by."""


def _doors(layout) -> np.ndarray:
    """Boolean over cell ids: free cells with walls on two opposite sides (the doors)."""
    w = np.pad(layout.wall_mask, 1)
    inner = w[1:-1, 1:-1]
    across = (w[1:-1, :-2] & w[1:-1, 2:]) | (w[:-2, 1:-1] & w[2:, 1:-1])
    return (across & ~inner).reshape(-1)


def _near_walls(layout) -> np.ndarray:
    """Boolean over cell ids: free cells with a wall among their 4 neighbours."""
    w = np.pad(layout.wall_mask, 1)
    near = w[1:-1, :-2] | w[1:-1, 2:] | w[:-2, 1:-1] | w[2:, 1:-1]
    return (near & ~layout.wall_mask).reshape(-1)


def _across(model: mujoco.MjModel, data: mujoco.MjData, g: int) -> tuple[float, float]:
    """(the geom's width across, m: twice the larger half size of its bounding box along its two
    local axes nearest the horizontal; its lowest point above the tabletop, m) at the
    configuration in ``data``. A pen held upright is its diameter across; one lying down, its
    length."""
    centre, half = model.geom_aabb[g, :3], model.geom_aabb[g, 3:]
    rot = data.geom_xmat[g].reshape(3, 3)
    upright = int(np.argmax(np.abs(rot[2])))
    across = 2 * float(max(h for i, h in enumerate(half) if i != upright))
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half + centre
    lowest = float((corners @ rot.T + data.geom_xpos[g])[:, 2].min())
    return across, lowest


def _what(model: mujoco.MjModel, g: int) -> str:
    name = _name(model, mujoco.mjtObj.mjOBJ_GEOM, g).removeprefix(PREFIX)
    body = (_name(model, mujoco.mjtObj.mjOBJ_BODY, int(model.geom_bodyid[g])) or f"body {model.geom_bodyid[g]}")
    body = body.removeprefix(PREFIX)
    return f"geom {name} of {body}" if name else f"a geom of {body}"


def _cell_size_for(width: float) -> float:
    """The smallest cell size in whole millimetres whose door fits ``width`` with ``MARGIN``
    either side."""
    return math.ceil((width + 2 * MARGIN) * 1000 - 1e-9) / 1000


def wall_cause(scene: ArmScene, tip_down: bool, reached: np.ndarray,
               rng: np.random.Generator | None = None, tries: int = TRIES) -> str:
    """Why the tool misses cells by the walls, in one clause, or "" when the walls are not
    the cause (no try over an unreached cell by the walls met a wall). ``reached``: boolean
    over cell ids, the cells some state of the arm is labelled with."""
    layout, cell = scene.layout, scene.cell
    rng = rng if rng is not None else np.random.default_rng(0)
    free = ~layout.wall_mask.reshape(-1)
    missed = free & ~np.asarray(reached, dtype=bool)
    doors = np.flatnonzero(missed & _doors(layout))
    by_walls = np.flatnonzero(missed & _near_walls(layout) & ~_doors(layout))
    cells = [*rng.permutation(doors), *rng.permutation(by_walls)][:tries]
    if not cells:
        return ""
    ik = TipIK(scene, tip_down)
    contact = ContactChecker(scene)
    walls = contact.walls
    model = scene.model
    met: Counter[int] = Counter()
    which: dict[int, Counter[str]] = {}
    widths: dict[int, tuple[float, float]] = {}
    tried = 0
    for c in cells:
        x, y = layout.xy(int(c))
        res = ik.solve_any(np.array([x * cell, y * cell]), scene.home, rng, restarts=RESTARTS)
        if not ik.ok(res):
            continue
        tried += 1
        g1, g2 = contact.contacts(res.q)
        hits = set()
        for a, b in zip(g1, g2):
            a, b = int(a), int(b)
            if walls[a]:
                a, b = b, a
            if walls[b] and scene.arm_geoms[a]:
                hits.add(a)
                which.setdefault(a, Counter())[_name(model, mujoco.mjtObj.mjOBJ_GEOM, b)] += 1
                widths[a] = max(widths.get(a, (0.0, 0.0)), _across(model, contact.data, a))
        met.update(hits)
    if not met:
        return ""
    g, count = met.most_common(1)[0]
    width, lowest = widths[g]
    names = ", ".join(w for w, _ in which[g].most_common(3))
    door = cell
    if tip_down:
        lift = math.ceil((WALL_HEIGHT + LIFT_MARGIN - lowest) * 1000)
        remedy = (f"hold a pen that rides the hand above the {WALL_HEIGHT * 100:g} cm walls, --tool stylus "
                  f"({STYLUS_LENGTH * 100:g} cm by default), or give a --tip-offset {lift} mm longer along the tool")
    else:
        remedy = f"give --cell-size {_cell_size_for(width):g} or more, for doors wider than the tool"
    return (f"{_what(model, g)}, {width * 1000:.1f} mm across at the walls' height, meets the walls "
            f"({names}) over {count} of {tried} unreached cells by the walls tried; a door is "
            f"{door * 1000:.1f} mm wide: {remedy}")


__all__ = ["REACH_OK", "wall_cause"]

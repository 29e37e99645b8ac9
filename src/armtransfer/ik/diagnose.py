"""Why an arm's tool finds no configuration over the table: the cause, measured, in one clause.

When IK puts the tool over no free cell (at a given mount, or at the best mount a search
found), ``why_unreachable`` tries a few cells spread around the base (``TRIES``) from
home and from random configurations, keeps the try that came closest, and names what
stopped it:

- the tool got there but the arm touches something: the bodies in contact and with what
  (``ContactChecker.contact_names``);
- the tool did not get there: how far the tip stayed from the cell, the joints at a limit,
  the tool's tilt from straight down or its height, whichever were off.

A try that fully succeeds means the table is reachable: the answer is then "".
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from armtransfer.ik.seeds import reach_bound, seed_cells
from armtransfer.ik.labels import cells_of_xy
from armtransfer.ik.scene import PREFIX, ArmScene, ContactChecker
from armtransfer.ik.solve import MAX_TIP_HEIGHT, TipIK

TRIES = 10
"""Cells tried: the one nearest the tip at home, the one halfway from the base to the table's
centre, and one at each of ``seeds.RING`` points around the base (``seed_cells`` with one
cell per point)."""
RESTARTS = 2
"""Random starting configurations per cell, after home."""
AT_LIMIT = 1e-3
"""A joint this close to a limit (rad) is at it."""


def _joints_at_limits(scene: ArmScene, q: np.ndarray) -> list[str]:
    m = scene.model
    out = []
    for j in range(m.njnt):
        a = m.jnt_qposadr[j]
        name = (mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) or f"#{j}").removeprefix(PREFIX)
        if q[a] <= scene.lower[a] + AT_LIMIT:
            out.append(f"{name} at its lower limit")
        elif q[a] >= scene.upper[a] - AT_LIMIT:
            out.append(f"{name} at its upper limit")
    return out


def why_unreachable(scene: ArmScene, tip_down: bool, rng: np.random.Generator | None = None,
                    tries: int = TRIES) -> str:
    """What stops the tool over the table, measured on the best of a few tries ("" when a try
    succeeds)."""
    layout, cell = scene.layout, scene.cell
    ik = TipIK(scene, tip_down)
    contact = ContactChecker(scene)
    rng = rng if rng is not None else np.random.default_rng(0)
    home_tip = contact.tip(scene.home)
    anchor, reach = reach_bound(scene)
    half = layout.width * cell / 2
    nearest = np.array([np.clip(anchor[0], -half, half), np.clip(anchor[1], -half, half), 0.0])
    if np.linalg.norm(anchor - nearest) > reach:
        return (f"the table's nearest point is {np.linalg.norm(anchor - nearest):.2f} m from the base, "
                f"{np.linalg.norm(anchor - nearest) - reach:.2f} m beyond the arm's reach of {reach:.2f} m")
    best: tuple[tuple, str] | None = None
    for c in [c for c in seed_cells(scene, home_tip, n=1) if layout.free[c]][:tries]:
        x, y = layout.xy(int(c))
        res = ik.solve_any(np.array([x * cell, y * cell]), scene.home, rng, restarts=RESTARTS)
        where = f"over cell ({x}, {y})"
        if ik.ok(res):
            landed = int(cells_of_xy(contact.tip(res.q), cell, layout))
            touching = contact.contact_names(res.q)
            if not touching and landed == c:
                return ""
            cause = (f"{where} the arm touches: {', '.join(touching)}" if touching
                     else f"{where} the tip lands over another cell")
            rank: tuple = (0, 0.0)
        else:
            parts = []
            if res.error > ik.tol:
                parts.append(f"the tip stays {res.error * 100:.1f} cm from {where.removeprefix('over ')}")
            if res.tilt > ik.tilt_tol:
                parts.append(f"the tool tilts {math.degrees(res.tilt):.0f} degrees from straight down "
                             f"(at most {math.degrees(ik.tilt_tol):.0f})")
            low = res.height - scene.clearance
            if not -1e-3 <= low <= MAX_TIP_HEIGHT:
                parts.append(f"the tool's lowest point is {abs(low) * 1000:.0f} mm {'above' if low > 0 else 'below'} "
                             "the tabletop")
            limits = _joints_at_limits(scene, res.q)
            if limits:
                parts.append(", ".join(limits))
            cause = "; ".join(parts) or f"IK does not settle {where}"
            rank = (1, res.error + res.tilt * 0.1)
        if best is None or rank < best[0]:
            best = (rank, cause)
    return best[1] if best is not None else "no free cell of the table to try"


__all__ = ["why_unreachable"]

"""State labelling with mink: configuration -> tool tip position -> shared cell id.

``cell_of_xy`` is the single rule every robot uses: the tip's (x, y) on the table,
divided by the cell size and rounded, is the cell; -1 when that is off the grid.
"""

from __future__ import annotations

import mink
import numpy as np

from armtransfer.ik.scene import ArmScene

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the layout is passed in from armtransfer.tasks, never imported
    from armtransfer.worlds.layout import Layout

OFF_TABLE = -1


def cell_of_xy(x: float, y: float, cell: float, layout: Layout) -> int:
    """The shared cell id under the point (x, y) (metres), or -1 off the grid."""
    return int(cells_of_xy(np.array([x, y]), cell, layout))


def cells_of_xy(xy: np.ndarray, cell: float, layout: Layout) -> np.ndarray:
    """Vectorised ``cell_of_xy`` over points [..., 2]; -1 off the grid."""
    return layout.ids_of(np.rint(np.asarray(xy)[..., :2] / cell))


class Labeller:
    """mink forward kinematics of one arm scene: tip position and shared-cell label."""

    def __init__(self, scene: ArmScene) -> None:
        self.scene = scene
        self.configuration = mink.Configuration(scene.model)

    def tip(self, q: np.ndarray) -> np.ndarray:
        self.configuration.update(np.asarray(q, dtype=float))
        return self.configuration.get_transform_frame_to_world(self.scene.tip, "site").translation()

    def label(self, q: np.ndarray) -> int:
        """Cell id under the tip at configuration q (-1 when off the table)."""
        p = self.tip(q)
        return cell_of_xy(p[0], p[1], self.scene.cell, self.scene.layout)

"""The 3D workspace: a world's plan stacked in levels above the table, cut into voxels.

A voxel is a cell of the plan at a level ``k`` (0 = on the table): the box of the cell's
square from ``k`` to ``k + 1`` level heights above the tabletop (the scene gives the height,
one cell size; ``ik.voxels``). Its id is ``k * n_cells + cell``, so the voxels of level 0
have the ids of the plan's cells: a 2D cell path *is* a voxel path at the table level, and a
task's start and goal cells are their voxels at level 0. A wall cell is solid up to
``wall_levels`` (the levels its wall box reaches into) and free above it, so a path may climb
over a low wall; a door is open at every level.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from armtransfer.worlds.layout import Layout

LEVELS = 3
"""How many levels the 3D workspace has."""


@dataclass(frozen=True)
class Voxels:
    """A layout's cells at ``levels`` levels, wall cells solid below ``wall_levels``."""

    layout: Layout
    levels: int = LEVELS
    wall_levels: int = 1

    def __post_init__(self) -> None:
        if self.levels < 1 or not 0 <= self.wall_levels <= self.levels:
            raise ValueError(f"bad voxel grid: {self.levels} levels, walls {self.wall_levels} levels high")

    @property
    def n_voxels(self) -> int:
        return self.levels * self.layout.n_cells

    @cached_property
    def free(self) -> np.ndarray:
        """Boolean over voxel ids: True where the voxel is not inside a wall."""
        free = np.concatenate([self.layout.free if k < self.wall_levels else np.ones(self.layout.n_cells, bool)
                               for k in range(self.levels)])
        free.setflags(write=False)
        return free

    def ids(self, cells: np.ndarray, levels: np.ndarray) -> np.ndarray:
        """Voxel ids of cells at levels; -1 where the cell is -1 or the level is outside 0..levels-1."""
        c, k = np.asarray(cells, dtype=np.int64), np.asarray(levels, dtype=np.int64)
        ok = (c >= 0) & (k >= 0) & (k < self.levels)
        return np.where(ok, k * self.layout.n_cells + c, -1)

    def cell_of(self, ids: np.ndarray) -> np.ndarray:
        """The plan's cell under each voxel id."""
        return np.asarray(ids, dtype=np.int64) % self.layout.n_cells

    def level_of(self, ids: np.ndarray) -> np.ndarray:
        return np.asarray(ids, dtype=np.int64) // self.layout.n_cells

    def xyk(self, voxel: int) -> tuple[int, int, int]:
        """(x, y, level) of one voxel id."""
        k, c = divmod(int(voxel), self.layout.n_cells)
        return (*self.layout.xy(c), k)


def cell_of_label(label: int, layout: Layout) -> int:
    """The plan's cell of a robot's label: the label itself for a 2D robot, the cell under
    the voxel for a 3D one (labels at or above ``n_cells`` are voxels above level 0)."""
    return int(label) % layout.n_cells

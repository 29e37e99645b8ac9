"""The tabletop workspace: the rooms layout laid on a table as low walls, built with
MuJoCo's ``MjSpec``.

Conventions (metres, world frame): the tabletop is the plane z = 0, the table's centre is
the world origin, and cell (x, y) of the layout is the square of side ``cell`` centred at
(x * cell, y * cell). The table is exactly the grid (51 x 51 cells), so a tool tip beyond
the grid is off the table. Walls are boxes ``wall_height`` tall covering exactly the wall
cells of ``layout.wall_mask`` (one box per run of wall cells along each wall segment, split
at the doors), so the MJCF walls and the wall cells agree by construction.

Workspace geoms have ``contype=0, conaffinity=1``: they collide with arm geoms
(``contype=1``) but never with each other.
"""

from __future__ import annotations

import numpy as np

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the layout is passed in from armtransfer.tasks, never imported
    from armtransfer.worlds.layout import Layout


DEFAULT_CELL = 0.01
"""One cell = 1 cm by default."""
WALL_HEIGHT = 0.02
TABLE_SIDE = 0.51
"""The table's side at the default cell size on the paper's 51 x 51 rooms (metres)."""


def world_cell(layout: Layout) -> float:
    """The default cell size on ``layout``: 1 cm on a 51-cell world (the paper's rooms), and on
    any other the size that keeps the table :data:`TABLE_SIDE` wide, so that an arm built for
    the rooms' table reaches a small world's table as it reaches that one."""
    return DEFAULT_CELL if layout.width == 51 else TABLE_SIDE / layout.width
TABLE_THICKNESS = 0.02


def wall_runs(layout: Layout) -> list[tuple[tuple[int, int], tuple[int, int]]]:
    """Runs of wall cells ((x0, y0), (x1, y1)), inclusive, along each wall segment."""
    runs = []
    for (x0, y0), (x1, y1) in layout.walls:
        dx, dy = int(np.sign(x1 - x0)), int(np.sign(y1 - y0))
        n = max(abs(x1 - x0), abs(y1 - y0)) + 1
        start = None
        for i in range(n + 1):
            inside = i < n
            if inside:
                x, y = x0 + dx * i, y0 + dy * i
                inside = layout.is_wall(x, y)
            if inside and start is None:
                start = (x0 + dx * i, y0 + dy * i)
            elif not inside and start is not None:
                runs.append((start, (x0 + dx * (i - 1), y0 + dy * (i - 1))))
                start = None
    return runs


def wall_boxes(layout: Layout, cell: float = DEFAULT_CELL,
               height: float = WALL_HEIGHT) -> list[tuple[np.ndarray, np.ndarray]]:
    """(centre, half sizes) of each wall box, in metres."""
    boxes = []
    for (x0, y0), (x1, y1) in wall_runs(layout):
        lo = np.array([min(x0, x1) - 0.5, min(y0, y1) - 0.5]) * cell
        hi = np.array([max(x0, x1) + 0.5, max(y0, y1) + 0.5]) * cell
        centre = np.array([*(lo + hi) / 2, height / 2])
        half = np.array([*(hi - lo) / 2, height / 2])
        boxes.append((centre, half))
    return boxes


def build_workspace(layout: Layout, cell: float = DEFAULT_CELL,
                    wall_height: float = WALL_HEIGHT):
    """The table scene as a ``mujoco.MjSpec`` (arms are attached to it)."""
    import mujoco  # here: tasks import this module and load no MuJoCo

    if not cell > 0:
        raise ValueError(f"cell size must be positive, got {cell}")
    spec = mujoco.MjSpec()
    spec.modelname = "workspace"
    spec.compiler.degree = False
    spec.option.timestep = 0.002
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.visual.headlight.ambient = [0.4, 0.4, 0.4]
    spec.add_material(name="table_mat", rgba=[0.82, 0.72, 0.58, 1])
    spec.add_material(name="wall_mat", rgba=[0.35, 0.3, 0.28, 1])
    world = spec.worldbody
    world.add_light(name="top_light", pos=[0, 0, 2.0], dir=[0, 0, -1])
    half = layout.width * cell / 2
    table = world.add_body(name="table")
    box = mujoco.mjtGeom.mjGEOM_BOX
    table.add_geom(name="table_top", type=box, size=[half, half, TABLE_THICKNESS / 2],
                   pos=[0, 0, -TABLE_THICKNESS / 2], material="table_mat", contype=0, conaffinity=1)
    for i, (centre, size) in enumerate(wall_boxes(layout, cell, wall_height)):
        table.add_geom(name=f"wall_{i}", type=box, size=[float(v) for v in size],
                       pos=[float(v) for v in centre], material="wall_mat", contype=0, conaffinity=1)
    world.add_camera(name="top", pos=[0, 0, 1.2], quat=[1, 0, 0, 0])
    return spec

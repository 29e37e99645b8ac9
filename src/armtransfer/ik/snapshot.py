"""One frame of an arm on the table, for ``render_mode="rgb_array"`` environments.

The arm is drawn by MuJoCo offscreen (``MUJOCO_GL=egl`` on a CPU) at a joint configuration,
from the same near-top-down orthographic camera as the rollout videos, with the cell grid
drawn as thin lines on the tabletop, the goal cell as a green disc and the cell under the
tool tip as a blue tile. Close it (or use ``with``) to free the GL context.
"""

from __future__ import annotations

import mujoco
import numpy as np

from armtransfer.ik.render import (
    GOAL_RGBA,
    START_RGBA,
    OwnsRenderer,
    offscreen_model,
    offscreen_renderer,
    render_with_markers,
    table_camera,
)
from armtransfer.ik.scene import ArmScene

GRID_RGBA = (0.3, 0.25, 0.2, 0.5)


class ArmSnapshot(OwnsRenderer):
    """Renders ``scene``'s arm at any configuration, marking the goal and the tip's cell."""

    def __init__(self, scene: ArmScene, width: int = 320, height: int = 240, samples: int = 4,
                 without: str = "draw nothing") -> None:
        self.scene = scene
        self.model = offscreen_model(scene, width, height, samples)
        self.data = mujoco.MjData(self.model)
        self.camera = table_camera(scene, width, height)
        self._grid = _grid_lines(scene)
        self.renderer = offscreen_renderer(self.model, height, width, self.model.ngeom + len(self._grid) + 16,
                                           without)

    def render(self, qpos: np.ndarray, goal_cell: int, tip_cell: int | None = None) -> np.ndarray:
        """[height, width, 3] uint8: the arm at ``qpos``, the goal and the tip's cell."""
        markers = list(self._grid)
        cell, layout = self.scene.cell, self.scene.layout
        thin = cell * 0.05
        if tip_cell is not None and tip_cell >= 0:
            x, y = layout.xy(int(tip_cell))
            markers.append((int(mujoco.mjtGeom.mjGEOM_BOX), np.array([0.45 * cell, 0.45 * cell, thin]),
                            np.array([x * cell, y * cell, thin]), np.array(START_RGBA)))
        gx, gy = layout.xy(int(goal_cell))
        markers.append((int(mujoco.mjtGeom.mjGEOM_CYLINDER), np.array([1.2 * cell, thin, 0.0]),
                        np.array([gx * cell, gy * cell, 2 * thin]), np.array(GOAL_RGBA)))
        return render_with_markers(self.renderer, self.model, self.data, self.camera, qpos, markers)


def _grid_lines(scene: ArmScene) -> list[tuple]:
    """Cell borders on the tabletop as decor lines (one per grid row and column)."""
    cell, layout = scene.cell, scene.layout
    lo, hi = (layout.lo - 0.5) * cell, (layout.hi + 0.5) * cell
    z = cell * 0.15  # above the tabletop, well below the 2 cm walls
    line = int(mujoco.mjtGeom.mjGEOM_LINE)
    rgba = np.array(GRID_RGBA)
    out = []
    for k in range(layout.width + 1):
        v = lo + k * cell
        out.append((line, 1.0, (np.array([v, lo, z]), np.array([v, hi, z])), rgba))
        out.append((line, 1.0, (np.array([lo, v, z]), np.array([hi, v, z])), rgba))
    return out

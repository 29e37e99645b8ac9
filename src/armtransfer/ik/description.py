"""What a compiled arm robot knows of its arm: a typed description, no MuJoCo import.

A discrete arm robot (``armtransfer.tasks.arms``) carries one of these as ``robot.arm``.
It holds everything needed to rebuild the exact MuJoCo scene the robot was compiled in
(``xml_path``, ``tool``, ``mount``, ``yaw``, ``cell_size``, ``layout``) and the joint
configuration and tip position of every state, so a path can be replayed in physics.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from armtransfer.ik.tool import Tool

if TYPE_CHECKING:  # the layout is passed in from armtransfer.tasks, never imported
    from armtransfer.worlds.layout import Layout


@dataclass(frozen=True, eq=False)
class ArmDescription:
    name: str
    """The arm's name: a built-in arm, or a bring-your-own arm's MJCF ``model`` attribute
    (its file stem when it has none), or the name the user gave it."""
    actions: str
    """The action model: ``joint``, ``cartesian`` or ``cartesian2``."""
    dof: int
    kind: str
    """``planar`` (vertical joint axes), ``spatial``, or ``custom`` (bring-your-own)."""
    qpos: np.ndarray
    """float [n_states, nq]: the joint configuration of every state."""
    tip: np.ndarray
    """float [n_states, 3]: the tool tip's position (m) at every state."""
    reach: float
    """The share of the layout's free cells that some state is labelled with."""
    cache: str
    """How the arrays were obtained: ``hit``, ``miss``, ``stale``, ``corrupt`` or ``off``."""
    key: str
    """The content hash the compiled arrays are cached under."""
    seconds: float
    """Wall time to compile (or load) the arrays."""
    cell_size: float
    mount: tuple[float, float, float]
    yaw: float
    xml_path: str
    tool: Tool
    """The tool point: a site or body of the arm file and an offset in its frame."""
    joint_step: float | None
    """Lattice step of the ``joint`` action model (rad); None for cartesian models."""
    layout: Layout
    lattice: Any = None
    """The ``joint`` model's lattice indices per state, when it has one."""
    mount_source: str = "given"
    """Where the mount came from: ``built-in``, ``given``, ``generated`` or ``automatic``."""
    chain: tuple[str, ...] = ()
    """The arm's joints from the base to the tool, as named in the arm file."""
    held: tuple[tuple[str, float], ...] = ()
    """Joints off that chain (fingers, jaws) and the home value each is held at."""
    clearance: float = 0.0
    """How far the tool's own geometry reaches past the tool point along its axis (m): the
    point rides that much higher than ``ik.solve.TIP_HEIGHT``, cells are read at the point."""
    clearance_geom: str = ""
    """The geom that reaches farthest past the point ("" when none does)."""
    levels: int = 0
    """0 for a robot on the table plane; for a spatial arm's ``joint`` robot, the levels of the
    3D workspace its labels (voxel ids, ``worlds.voxels``) number."""
    moved: tuple[int, ...] = ()
    """A spatial ``joint`` robot's moved joints (indices into ``chain``); the rest are held."""

    def clearance_note(self) -> str:
        """One line when the tool's geometry reaches past the tool point, else ""."""
        if self.clearance <= 0:
            return ""
        return (f"the tool's geometry ({self.clearance_geom}) reaches {self.clearance * 1000:.1f} mm past its point: "
                "the lowest point rides 4 mm above the table, the cell is read at the point")

    @property
    def tip_site(self) -> str | None:
        return self.tool.site

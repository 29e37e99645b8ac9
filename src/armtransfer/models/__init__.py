"""The project's arms: one folder per arm with its MJCF and a README.

Every arm has a site named ``tip`` (the tool tip), a ``home`` keyframe, hinge joints named
``joint1..jointN`` and a position actuator per joint named like the joint. ``ARMS`` maps an
arm name to where its XML is, how many joints it has, which action models it supports
(first = default) and how it is mounted relative to the table (see ``src/armtransfer/ik/workspace.py``:
the tabletop is z = 0 and cell (x, y) is centred at (x * cell, y * cell)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

MODELS_DIR = Path(__file__).resolve().parent


@dataclass(frozen=True)
class ArmInfo:
    name: str
    dof: int
    kind: str
    """"planar" (vertical joint axes, stylus down to the table) or "spatial"."""
    actions: tuple[str, ...]
    mount_pos: tuple[float, float, float]
    """Position of the arm's base frame in the world (m), at cell size 1 cm. Planar arms
    scale their mount with the cell size; spatial arms keep theirs."""
    mount_yaw: float = 0.0
    """Rotation of the base frame about the world z axis (rad)."""
    tip_down: bool = False
    """Spatial arms keep the tool pointing straight down."""
    joint_step: float = 0.05
    """Lattice step of the ``joint`` action model (rad)."""
    notes: str = ""
    tip_site: str = "tip"
    extra: dict = field(default_factory=dict)

    @property
    def xml_path(self) -> Path:
        return MODELS_DIR / self.name / f"{self.name}.xml"


# Planar arms hang above the wall junction at cell (-3, 3) rather than the table centre:
# their elbow cannot fold completely, so a small disc around the shoulder axis is out of
# reach, and over the junction that disc covers mostly wall cells instead of the Table I
# start cell (0, 0).
PLANAR_MOUNT = (-0.03, 0.03, 0.0)

ARMS: dict[str, ArmInfo] = {
    "planar2": ArmInfo("planar2", 2, "planar", ("joint", "cartesian"), PLANAR_MOUNT,
                       joint_step=0.05,
                       notes="links 0.20 + 0.20 m; unreachable inner disc r = 2.8 cm"),
    "planar3": ArmInfo("planar3", 3, "planar", ("joint", "cartesian"), PLANAR_MOUNT,
                       joint_step=0.12,
                       notes="links 0.16 + 0.13 + 0.11 m; joint lattice step 0.12 rad"),
    "planar4": ArmInfo("planar4", 4, "planar", ("joint", "cartesian"), PLANAR_MOUNT,
                       joint_step=0.25,
                       notes="links 0.13 + 0.11 + 0.09 + 0.07 m; joint lattice step 0.25 rad"),
    "ur5e_like": ArmInfo("ur5e_like", 6, "spatial", ("cartesian",), (0.0, -0.42, 0.0),
                         mount_yaw=-math.pi / 2, tip_down=True,
                         notes="UR5e DH; beside the table, 0.42 m in front of its centre"),
    "panda_like": ArmInfo("panda_like", 7, "spatial", ("cartesian",), (0.0, -0.40, 0.0),
                          mount_yaw=math.pi / 2, tip_down=True,
                          notes="Franka Panda DH; beside the table, 0.40 m in front of its centre"),
}

"""Action models: how an arm's actions move it.

* ``joint``: +delta / -delta on one joint (2 * DOF actions, ``q1+``, ``q1-``, ...). Only the
  moved joint turns, so the tip moves along an arc about that joint's axis (the paper's
  Fig. 2(a) robot). Planar arms only; delta is the arm's lattice step.
* ``cartesian`` / ``cartesian2``: the tip moves k = 1 / 2 cells along +y, -y, +x, -x
  (actions F, B, R, L, as the grid robots ``fine`` and ``coarse``); the joint
  configuration for each cell comes from inverse kinematics.
"""

from __future__ import annotations

from dataclasses import dataclass

from armtransfer.errors import UnknownArmError

CARTESIAN_NAMES = ("F", "B", "R", "L")


@dataclass(frozen=True)
class ActionModel:
    name: str
    kind: str  # "joint" or "cartesian"
    cells: int = 1
    """Cells per action for cartesian models."""

    def action_names(self, dof: int) -> tuple[str, ...]:
        if self.kind == "joint":
            return tuple(f"q{j + 1}{sign}" for j in range(dof) for sign in ("+", "-"))
        return CARTESIAN_NAMES


ACTION_MODELS = {
    "joint": ActionModel("joint", "joint"),
    "cartesian": ActionModel("cartesian", "cartesian", 1),
    "cartesian2": ActionModel("cartesian2", "cartesian", 2),
}


def action_model(name: str) -> ActionModel:
    if name not in ACTION_MODELS:
        raise UnknownArmError(
            f"unknown action model {name!r}; valid action models: {', '.join(ACTION_MODELS)}"
        )
    return ACTION_MODELS[name]

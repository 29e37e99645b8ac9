"""The shared cells as a robot of their own: how a robot without state numbers gets paid.

A continuous robot (``ik.continuous``) has no table of states, only a label, the cell under
its tool point. The transfer methods' arrays (``learning.methods``) are built per state of a
``DiscreteRobot``; built for ``tasks.robot.cell_robot``, whose states are the layout's cells each
labelled with itself, they are per-cell arrays that the linear learner indexes by label. The
methods that apply are those whose transfer is a reward term on labels alone
(:data:`CELL_METHODS`).
"""

from __future__ import annotations

from collections.abc import Sequence

from armtransfer.errors import InvalidParameterError
from armtransfer.learning import methods as registry
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.lazy_registry import Names
from armtransfer.learning.shaping import Shaping
from armtransfer.learning.trajectory import Trajectory
from armtransfer.worlds.layout import Layout
from armtransfer.tasks.robot import cell_robot

CELL_METHODS = Names(registry.METHODS, lambda name, m: not (m.chooses or m.macros or m.is_baseline) and name != "dense")
"""The methods (a plugin's too: it is paid on labels alone) a robot known only by its label can learn with: no transfer and the reward terms
paid by the cell reached (``dense`` needs distances over the robot's own states; ``guided``
and its kin model a table of moves; ``mapping`` needs state numbers for its macros)."""


def check_method(method: str) -> str:
    registry.get(method)  # an unknown name: the registry's one-line error
    if method not in CELL_METHODS:
        raise InvalidParameterError(
            f"method {method!r} does not apply to a continuous robot; valid methods: {', '.join(CELL_METHODS)}")
    return method


def cell_shaping(method: str, layout: Layout, trajs: Trajectory | Sequence[Trajectory] | None,
                 K: float | str | None, config: LearnerConfig, levels: int = 1) -> Shaping | None:
    """Method ``method``'s shaping arrays over the cells of ``layout`` (None for ``none``);
    ``levels`` > 1: over the voxels of the 3D workspace (a spatial arm's labels)."""
    check_method(method)
    if not registry.get(method).shaped:
        return None
    return registry.build_shaping(method, cell_robot(layout, levels), trajs, K, config.step_reward,
                                  gamma=config.gamma)

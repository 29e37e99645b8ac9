"""Method ``guided``: robot 2 learns, while it explores, what its own actions do to its label,
and uses that to move towards the next cells of the transferred trajectory.

Why: with Q = 0 at the start and a step reward of -1, every untried action ties at the top of
Q, so at a new state Algorithm 1 does not know which of its actions leads on along the
trajectory until it has tried them there. Even a perfect state potential (``oracle``) leaves
that choice to chance at every new state.

One module per mechanism, each with the record of what it learns during a trial:

* ``displacement``: what each move did to the label, generalised to untried pairs by the
  nearest states in robot 2's own configuration space;
* ``tip``: for a robot whose actions move a joint, where its tip is as a function of its joints;
* ``progress``: how far along each trajectory robot 2 has come, and the score of a position;
* ``fill``: learning real-time search on that score, with the tip model;
* ``planner``: value iteration after every episode over the moves robot 2 has tried;
* ``choice``: the epsilon-greedy of the exploration phase over Q and the predicted score;
* ``params``: the defaults, and ``model``: the records the kernel is handed and how they are built.

In the exploration phase only (the first ``episodes`` episodes; 1: until the goal is first
reached) the model chooses; afterwards Algorithm 1's epsilon-greedy chooses alone on Q:
SARSA(lambda)'s updates during an episode, the plan after it; the displacement model never
biases the greedy path. The model never reads the robot's transition table nor the map; the
kernel reads ``next_state`` only to take the move chosen (a test changes every transition not
tried in a run of several episodes and gets the same run, bit for bit; the convergence check
after each episode, the experimenter's, follows the greedy path through the table as for every
method)."""

from __future__ import annotations

from pathlib import Path

from armtransfer.learning import jitcache
from armtransfer.learning.guide import choice, displacement, fill, model, planner, progress, tip
from armtransfer.learning.guide.model import Guide, Model, build, corridor_prior, inactive, new_model
from armtransfer.learning.guide.params import (
    BLOCKED, EPISODES, FADE, FILL, FILL_COST, GIVE_UP, KNN, MEMORY, PLAN, PLAN_CAP, PLAN_TOL, RADIUS, REACH, ROUTE, SUCCESSORS, TIP,
    TIP_ANCHOR, TIP_NEAREST, TIP_ORDER, TIP_RIDGE, UNTRIED, WEIGHT, WINDOW, Params,
)
from armtransfer.learning.guide.tip import tip_features, uses_tip

__all__ = [
    "BLOCKED", "EPISODES", "FADE", "FILL", "FILL_COST", "GIVE_UP", "KNN", "MEMORY", "PLAN", "PLAN_CAP", "PLAN_TOL", "RADIUS", "REACH", "ROUTE",
    "SUCCESSORS", "TIP", "TIP_ANCHOR", "TIP_NEAREST", "TIP_ORDER", "TIP_RIDGE", "UNTRIED", "WEIGHT", "WINDOW",
    "FILES", "Guide", "Model", "Params", "build", "corridor_prior", "inactive", "new_model", "tip_features", "uses_tip",
]

FILES = sorted(Path(__file__).parent.glob("*.py"))
"""The guide's source files. Its jitted functions call each other across them, and the learner's
kernels call them; numba's cache notices an edit to a function's own file only, so every kernel
that calls into the guide is compiled afresh when any of these changes (``jitcache``)."""

for _module in (displacement, tip, progress, fill, planner, choice, model):
    jitcache.invalidate_stale(_module.__name__, [v for v in vars(_module).values()
                                                 if getattr(getattr(v, "py_func", None), "__module__", None)
                                                 == _module.__name__], FILES)
del _module

"""The guide's parameters: the defaults, what each is and how it was chosen, and the record the
kernel reads them from. How the chosen values were selected, candidate by candidate, is in
docs/research-log.md under "guide parameters"."""

from __future__ import annotations

from typing import NamedTuple

WINDOW = 2.0
"""Cells of trajectory ahead of the progress index the score reads; chosen by research/select_defaults.py --method guided."""
REACH = 1.0
"""A trajectory cell is reached within this many cells of the label; chosen by research/select_defaults.py --method guided."""
KNN = 8
"""Neighbours in configuration space an untried pair's prediction averages; chosen by select_defaults.py --method guided."""
MEMORY = 256
"""States per action remembered for the neighbour search (the most recent); not tuned."""
WEIGHT = 2.0
"""Preference per cell of predicted progress, in units of Q; chosen by research/select_defaults.py --method guided."""
BLOCKED = True
"""Whether a blocked move is generalised to nearby states like any effect; chosen by select_defaults.py --method guided."""
GIVE_UP = 100
"""Moves without progress before the next cell (at s_tg: the trajectory) is given up on (0: never); select_defaults.py."""
EPISODES = 1
"""The model chooses in this many first episodes (1: the exploration phase, as for the mapping's macros); not tuned."""
PLAN = True
"""Whether robot 2 plans over the moves it has tried, after every episode (``guide.planner``); not tuned."""
PLAN_TOL = 1e-12
"""A value changing by at most this re-plans no predecessor; a numerical guard for wind, checked on held-out pairs."""
PLAN_CAP = 1000
"""Backups per planning at most, in robot 2's number of states (a guard: gamma = 1 can loop); not tuned."""
UNTRIED = 1e-9
"""The planned Q of an untried pair: just above 0, the bound on every return, so it wins ties; not tuned."""
RADIUS = 0.0
"""Cells from the trajectories within which an untried pair keeps the full optimism UNTRIED
(``model.corridor_prior``); only read when FADE > 0."""
FADE = 0.0
"""Optimism lost per cell beyond RADIUS, in units of Q (0: none, ``plan`` and ``guided``); the
method ``corridor`` sets its own, chosen on the dev suite (docs/research-log.md)."""
ROUTE = 0.0
"""Optimism lost per cell of trajectory left beyond the nearest trajectory cell, in units of Q (0:
none); ``model.corridor_prior``."""
SUCCESSORS = 4
"""Distinct observed successors kept per pair (a move and its wind push are at most 2); not tuned."""
TIP = None
"""Whether robot 2 learns where its tip is (``guide.tip``); None: when its actions move a joint; not tuned."""
TIP_ANCHOR = True
"""Whether the score starts from the tip's estimate inside the cell, not its centre; select_defaults.py --method guided-tip."""
TIP_ORDER = 3
"""The tip model's features multiply cos or sin of at most this many joints (exact up to 3 planar joints); not tuned."""
TIP_RIDGE = 1e-3
"""Ridge penalty of the tip model's least squares (prior: the tip stays put); select_defaults.py --method guided-tip."""
TIP_NEAREST = 8
"""An untried move is predicted blocked if blocked at this many nearest tried states; select_defaults.py --method guided-tip."""
FILL = None
"""The fill's cost per move in cells (``guide.fill``); None: FILL_COST with the tip model, 0 (off) without; not tuned."""
FILL_COST = 0.25
"""The fill's cost per move with the tip model, in cells; chosen by research/select_defaults.py --method guided-fill."""


class Params(NamedTuple):
    """The guide's parameters as the kernel reads them (the defaults above; ``model.build``)."""

    window: float
    reach: float
    knn: int
    memory: int
    weight: float
    episodes: int
    blocked: bool
    give_up: int
    plan: bool
    plan_tol: float
    tip: bool
    tip_ridge: float
    tip_nearest: int
    tip_anchor: bool
    fill: float
    """Cells per move; 0: off."""

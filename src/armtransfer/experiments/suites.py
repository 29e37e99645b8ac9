"""The benchmark's suites: fixed, versioned sets of transfer cases that ``armtransfer
benchmark --suite NAME`` runs.

A suite is one or more sections; a section is a list of cases (source robot, target robot,
task, wind) and how each is run: how many source seeds (robot 1 learns the task again for
each, and its converged greedy path is the trajectory handed over), how many trials of every
method per source seed, the step cap of a trial, and the first-exposure budget of the
success rate. A suite marked ``held_out`` was never used to choose a parameter of any method;
parameters are chosen on ``dev`` only. Changing what a suite runs means a new ``version``, so
a report's numbers always name the suite they came from.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from armtransfer.errors import InvalidParameterError

METHODS = ("none", "pseudo", "dense", "guided", "plan", "goal-only", "pseudo-plan", "corridor")
"""The methods every suite runs (those this build's registry has), each beside its baseline."""

MIN_SEEDS_FOR_CLAIM = 10
"""A report states that a method is faster or slower than its baseline only from at least this
many paired source seeds; with fewer it gives the numbers and makes no claim."""

BUDGET_FACTOR = 100
"""Success within budget: the goal first reached within this many times the target robot's
shortest path from start to goal (in its own steps)."""


CELLS = ("any", "even", "odd")
"""Which cells a drawn task's start and goal may be on: ``even`` (both coordinates even: the
cells every parameter of this package was chosen on, ``research/select_defaults.py``), ``odd``
(at least one coordinate odd: cells no choice ever saw) or ``any``."""


DEFAULT_WORLD = "rooms"

STATES = ("discrete", "continuous")
"""What robot 2's state is in a case: ``discrete`` (its compiled table, learned by the tabular
SARSA(lambda)) or ``continuous`` (an arm's joint configuration with MuJoCo at every move, learned
by the linear learner over tile coding: ``armtransfer.transfer(..., state="continuous")``'s)."""


@dataclass(frozen=True)
class Case:
    source: str
    target: str
    task: int | str | None
    """A task of the case's world (a Table I number on the rooms, a task name or number of another
    world); None: start and goal drawn per source seed over the whole world."""
    wind: float = 0.0
    distance: tuple[int, int | None] | None = None
    """A drawn task's shortest path for the finer robot lies in [low, high) (high None: no
    limit); None: at least ``benchmark.MIN_DISTANCE``."""
    cells: str = "any"
    """Which cells a drawn task's start and goal are on (``CELLS``)."""
    world: str = "rooms"
    """The world the robots move in: a name ``armtransfer.worlds.resolve.world`` knows (``rooms``,
    the paper's; ``rooms11``, ``rooms15``, ``generated:SEED[:SIDE]``)."""
    state: str = "discrete"
    """Robot 2's state (``STATES``): ``continuous`` runs the target arm's continuous counterpart
    (``tasks.continuous.continuous_arm(target)``); robot 1 stays table-based either way."""
    noise: float = 0.0
    """A continuous target's actuation noise sigma (``ik.continuous``); 0 for a discrete one."""

    def __post_init__(self) -> None:
        if self.state not in STATES:
            raise InvalidParameterError(f"unknown state {self.state!r}; valid states: {', '.join(STATES)}")
        if self.state == "discrete" and self.noise:
            raise InvalidParameterError("noise (actuation noise) applies to a continuous target; valid noise: 0")
        if self.state == "continuous" and self.wind:
            raise InvalidParameterError("a continuous target has no wind; valid wind: 0")

    @property
    def label(self) -> str:
        task = "random task" if self.task is None else f"task {self.task}"
        if self.task is None and self.distance is not None:
            lo, hi = self.distance
            task += f" of {lo}+ steps" if hi is None else f" of {lo}-{hi - 1} steps"
        if self.task is None and self.cells != "any":
            task += f" on {self.cells} cells"
        wind = f", wind {self.wind:g}" if self.wind else ""
        world = f", in {self.world}" if self.world != DEFAULT_WORLD else ""
        target = self.target
        if self.state == "continuous":
            target += " continuous" + (f" (noise {self.noise:g})" if self.noise else "")
        return f"{self.source} -> {target}, {task}{wind}{world}"


DEFAULT_LEARNERS = ("sarsa",)


@dataclass(frozen=True)
class Section:
    name: str
    description: str
    cases: tuple[Case, ...]
    source_seeds: int
    trials: int
    """Trials of every method per source seed."""
    max_total_steps: int
    """A trial's step cap: a first exposure not reached by then is censored there."""
    learners: tuple[str, ...] = ("sarsa",)
    """The learners every method runs on (``armtransfer.learning.learners``), each method beside
    the baseline run by the same learner; an outside learner runs ``none`` and the reward-term
    methods."""
    methods: tuple[str, ...] | None = None
    """The methods this section runs (each with its baselines), of those the benchmark runs;
    None: all of them."""

    def to_dict(self) -> dict:
        """The section as stored and reported; the default learners are left out, so a suite that
        runs the built-in learner alone keeps the store key and the bytes it had before."""
        out = asdict(self)
        for case in out["cases"]:  # a case of the default world keeps the bytes it had before worlds
            if case["world"] == DEFAULT_WORLD:
                del case["world"]
            if case["state"] == "discrete":  # a discrete case keeps the bytes it had before states
                del case["state"], case["noise"]
        if self.learners == DEFAULT_LEARNERS:
            del out["learners"]
        else:
            out["learners"] = list(self.learners)
        if self.methods is None:  # every method: the bytes a section had before sections chose
            del out["methods"]
        else:
            out["methods"] = list(self.methods)
        return out


@dataclass(frozen=True)
class Suite:
    name: str
    version: int
    held_out: bool
    description: str
    sections: tuple[Section, ...]

    def to_dict(self) -> dict:
        return {"name": self.name, "version": self.version, "held_out": self.held_out,
                "description": self.description, "methods": list(METHODS), "budget_factor": BUDGET_FACTOR,
                "sections": [s.to_dict() for s in self.sections]}


def _both_ways(pairs: list[tuple[str, str]], tasks: tuple[int | None, ...], wind: float = 0.0) -> tuple[Case, ...]:
    return tuple(Case(a, b, t, wind) for s, d in pairs for a, b in ((s, d), (d, s)) for t in tasks)


TRIALS = 3
"""Trials of every method per source seed in the held-out sections: enough to estimate how
much of the spread lies between source seeds (reported) beside the spread within them."""

ARM_TRIALS = 2
"""Trials per source seed on the arms (``embodiment``): a method's trials run two at a time on two
cores, so a third trial doubles the wall time of the section that takes 80% of ``standard``'s
(measured, docs/benchmark.md); two per seed still give the one-way ANOVA its within-seed spread."""

BANDS = ((10, 20), (20, 30), (30, 45), (45, 65), (65, None))
"""The drawn tasks' distance bands of ``random``; the shortest, below 20 steps, is a length no
choice of a parameter saw (``research/select_defaults.py`` drew 20 steps and more)."""

PAPER = Section(
    "paper", "the paper's Table I tasks 1-4, coarse -> fine and fine -> coarse",
    _both_ways([("coarse", "fine")], (1, 2, 3, 4)), source_seeds=10, trials=TRIALS, max_total_steps=2_000_000)
RANDOM = Section(
    "random", "start and goal drawn per source seed on cells no parameter was chosen on (at least one odd "
    "coordinate), in five distance bands from 10-19 to 65+ steps, coarse <-> fine",
    tuple(Case(a, b, None, distance=band, cells="odd") for a, b in (("coarse", "fine"), ("fine", "coarse"))
          for band in BANDS),
    source_seeds=10, trials=TRIALS, max_total_steps=2_000_000)
EMBODIMENT = Section(
    "embodiment", "arms that move their joints (2-4 joints) and a generated planar arm, both directions, "
    "Table I tasks 1-4",
    _both_ways([("planar2:joint", "planar3:joint"), ("planar3:joint", "planar4:joint"),
                ("gen:planar:3:1:joint", "planar2:joint")], (1, 2, 3, 4)),
    source_seeds=10, trials=ARM_TRIALS, max_total_steps=1_000_000)
WIND_LEVELS = (0.01, 0.05, 0.1)
WIND = Section(
    "wind", "Table I tasks 1-4, coarse -> fine, with wind 0.01, 0.05 and 0.1 (a move is blown one cell aside)",
    tuple(Case("coarse", "fine", t, w) for w in WIND_LEVELS for t in (1, 2, 3, 4)), source_seeds=10,
    trials=TRIALS, max_total_steps=2_000_000)
DEV = Section(
    "dev", "the development cases parameters may be chosen on: tasks drawn on even cells (coarse -> fine), "
    "as every earlier choice was, and the robot pairs earlier parameters were chosen on (ur5e_like:cartesian -> "
    "planar2:joint task 3, planar3:joint -> planar4:cartesian task 4)",
    (Case("coarse", "fine", None, cells="even"), Case("ur5e_like:cartesian", "planar2:joint", 3),
     Case("planar3:joint", "planar4:cartesian", 4)),
    source_seeds=10, trials=2, max_total_steps=2_000_000)
FAST = Section(
    "fast", "coarse -> fine task 1, two source seeds: checks the whole protocol in seconds",
    (Case("coarse", "fine", 1),), source_seeds=2, trials=2, max_total_steps=300_000)
SMALL_LEARNERS = ("sarsa", "dqn", "ppo")
"""The learners of ``small``: the built-in SARSA(lambda) and stable-baselines3's DQN and PPO (the
``sb3`` extra; ``armtransfer.learning.sb3``), which run ``none`` and the reward-term methods."""

SMALL = Section(
    "small", "the small rooms worlds rooms11 and rooms15, task 2 (north-east room to south-west), coarse -> fine, "
    "learned by SARSA(lambda) and by stable-baselines3's DQN and PPO; rooms11 task 3 was the dev case the SB3 "
    "settings and this step cap were chosen on (source seeds 100 and 101 of research/sb3_small.py)",
    (Case("coarse", "fine", 2, world="rooms11"), Case("coarse", "fine", 2, world="rooms15")),
    source_seeds=10, trials=2, max_total_steps=25_000, learners=SMALL_LEARNERS)

VOXELS = Section(
    "voxels", "arms moving their joints with the tool off the table, over the 3D workspace of rooms11 (3 levels, "
    "walls 1 level high), task 2: planar2:joint -> ur5e_like:joint (a 2D path, paid at level 0) and "
    "ur5e_like:joint -> panda_like:joint (a path of voxels); none and pseudo",
    (Case("planar2:joint", "ur5e_like:joint", 2, world="rooms11"),
     Case("ur5e_like:joint", "panda_like:joint", 2, world="rooms11")),
    source_seeds=10, trials=ARM_TRIALS, max_total_steps=1_000_000, methods=("none", "pseudo"))

CONTINUOUS_CAP = 300_000
"""The step cap of a continuous target's trial (``voxels-continuous``): every move runs MuJoCo
(and, with actuation noise, the Python loop), so a trial costs far more per step than a
table-based one."""

VOXELS_CONTINUOUS = Section(
    "voxels-continuous", "the voxels cases with a continuous target: the joint robot's arm in its joint "
    "configuration with MuJoCo at every move, actuation noise 0.1, learned by linear SARSA(lambda) over hashed "
    "tiles; robot 1 is table-based: planar2:joint -> ur5e_like (6 joints), ur5e_like:joint -> panda_like "
    "(7 joints), rooms11 task 2; none and pseudo",
    (Case("planar2:joint", "ur5e_like:joint", 2, world="rooms11", state="continuous", noise=0.1),
     Case("ur5e_like:joint", "panda_like:joint", 2, world="rooms11", state="continuous", noise=0.1)),
    source_seeds=10, trials=ARM_TRIALS, max_total_steps=CONTINUOUS_CAP, methods=("none", "pseudo"))

SUITES: dict[str, Suite] = {
    s.name: s
    for s in (
        Suite("paper", 3, True, PAPER.description, (PAPER,)),
        Suite("random", 3, True, RANDOM.description, (RANDOM,)),
        Suite("embodiment", 3, True, EMBODIMENT.description, (EMBODIMENT,)),
        Suite("wind", 3, True, WIND.description, (WIND,)),
        Suite("standard", 3, True, "the held-out union: paper, random, embodiment and wind",
              (PAPER, RANDOM, EMBODIMENT, WIND)),
        Suite("dev", 3, False, DEV.description, (DEV,)),
        Suite("fast", 2, False, FAST.description, (FAST,)),
        Suite("small", 1, True, SMALL.description, (SMALL,)),
        Suite("voxels", 2, True, "arms moving their joints over the 3D workspace of rooms11, table-based and "
              "continuous targets: " + VOXELS.description + "; " + VOXELS_CONTINUOUS.description,
              (VOXELS, VOXELS_CONTINUOUS)),
    )
}
"""Every suite by name."""


def get(name: str) -> Suite:
    """The suite called ``name``; an unknown name is a one-line error listing the valid ones."""
    try:
        return SUITES[name]
    except (KeyError, TypeError):
        raise InvalidParameterError(f"unknown suite {name!r}; valid suites: {', '.join(SUITES)}") from None

"""What a benchmark suite is: fixed, versioned sets of transfer cases that ``armtransfer
benchmark --suite NAME|FILE`` runs (the suites themselves: ``experiments.suites``).

A suite is one or more sections; a section is a list of cases (source robot, target robot,
task, wind) and how each is run: how many source seeds (robot 1 learns the task again for
each, and its converged greedy path is the trajectory handed over), how many trials of every
method per source seed, the step cap of a trial, and the first-exposure budget of the
success rate. A suite marked ``held_out`` was never used to choose a parameter of any method;
parameters are chosen on ``dev`` only. Changing what a suite runs means a new ``version``, so
a report's numbers always name the suite they came from.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

from armtransfer.errors import InvalidParameterError
from armtransfer.experiments.stored_form import leave_out
from armtransfer.experiments.run import STATES as STATES  # discrete (its table) or continuous (an arm's joints)
from armtransfer.worlds.resolve import DEFAULT_WORLD as DEFAULT_WORLD, layout_of_data

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
    start: tuple[int, int] | None = None
    """The task's start cell (x, y), given with :attr:`goal` instead of a ``task``."""
    goal: tuple[int, int] | None = None

    def __post_init__(self) -> None:
        if self.state not in STATES:
            raise InvalidParameterError(f"unknown state {self.state!r}; valid states: {', '.join(STATES)}")
        if self.state == "discrete" and self.noise:
            raise InvalidParameterError("noise (actuation noise) applies to a continuous target; valid noise: 0")
        if self.state == "continuous" and self.wind:
            raise InvalidParameterError("a continuous target has no wind; valid wind: 0")
        if (self.start is None) != (self.goal is None) or (self.start is not None and self.task is not None):
            raise InvalidParameterError("a case gives a task, or a start and a goal, or neither")

    @property
    def label(self) -> str:
        if self.start is not None and self.goal is not None:
            task = f"({self.start[0]},{self.start[1]}) -> ({self.goal[0]},{self.goal[1]})"
        else:
            task = "random task" if self.task is None else f"task {self.task}"
        if self.task is None and self.distance is not None:
            lo, hi = self.distance
            task += f" of {lo}+ steps" if hi is None else f" of {lo}-{hi - 1} steps"
        if self.task is None and self.cells != "any":
            task += f" on {self.cells} cells"
        wind = f", wind {self.wind:g}" if self.wind else ""
        world = f", in {self.world.partition('#')[0]}" if self.world != DEFAULT_WORLD else ""
        target = self.target
        if self.state == "continuous":
            target += " continuous" + (f" (noise {self.noise:g})" if self.noise else "")
        return f"{self.source} -> {target}, {task}{wind}{world}"


DEFAULT_LEARNERS = ("sarsa",)

CASE_DEFAULTS = {"world": DEFAULT_WORLD, ("state", "noise"): ("discrete", 0.0), ("start", "goal"): (None, None)}
"""The fields a stored case leaves out at these values (``stored_form``): the paper's rooms; a
discrete target (with no noise); a task or a drawn one (no cells)."""

SECTION_DEFAULTS = {"learners": DEFAULT_LEARNERS, "methods": None}
"""The fields a stored section leaves out at these values: the built-in learner alone; every method."""

SUITE_DEFAULTS: dict[str, dict] = {"worlds": {}}
"""The fields a stored suite leaves out at these values: no layout file's world."""


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
        """The section as stored and reported, its cases' and its own fields at their defaults
        (:data:`CASE_DEFAULTS`, :data:`SECTION_DEFAULTS`) left out."""
        out = asdict(self)
        out["cases"] = tuple(leave_out(case, CASE_DEFAULTS) for case in out["cases"])
        out = leave_out(out, SECTION_DEFAULTS)
        for name in ("learners", "methods"):
            if name in out:
                out[name] = list(out[name])
        return out


@dataclass(frozen=True)
class Suite:
    name: str
    version: int
    held_out: bool
    description: str
    sections: tuple[Section, ...]
    methods: tuple[str, ...] | None = None
    """The methods a suite file names (each section runs them); None: :data:`METHODS`."""
    worlds: dict[str, dict] = field(default_factory=dict)
    """The layout files' worlds the cases name, by id (``suite_files.world_id``): their content
    (``worlds.files.layout_data``), so a stored suite needs no file to be made again."""

    def to_dict(self) -> dict:
        out = {"name": self.name, "version": self.version, "held_out": self.held_out,
               "description": self.description, "methods": list(METHODS if self.methods is None else self.methods),
               "budget_factor": BUDGET_FACTOR, "sections": [s.to_dict() for s in self.sections],
               "worlds": {k: self.worlds[k] for k in sorted(self.worlds)}}
        return leave_out(out, SUITE_DEFAULTS)

    def layouts(self) -> dict:
        """The worlds of :attr:`worlds`, by id (``worlds.layout.Layout``)."""
        return {k: layout_of_data(v, f"suite {self.name!r}: world {k!r}") for k, v in self.worlds.items()}

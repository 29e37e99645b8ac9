"""Running a benchmark suite: every case, every source seed, every method beside its baseline.

For each case and source seed, robot 1 (the source) learns the task without transfer and
its converged greedy path is the trajectory handed over, so the source's own learning is a
random effect of the benchmark, not one fixed path. Then every method of
``suites.METHODS`` that this build's registry has, and the baseline each names, run
``trials`` trials on robot 2 from the same random streams (common random numbers), so a
method and its baseline are paired trial by trial and seed by seed.

A suite is planned (:func:`plan`) into runs of the result store
(``armtransfer.experiments.benchmark_runs``): one source run per (case, source seed) and one
run per trial of every method, which any executor may run in any order; the records are
then assembled from the runs' results in the plan's order (:meth:`Plan.records`), so they do
not depend on where or when each run ran. :func:`run_suite` runs them all in this process.

A source that does not converge, or a method that refuses the case, is recorded (counted
as a failure in the statistics), never dropped. Every random draw comes from
``SeedSequence([seed, section, case, source seed, ...])``, so the same seed gives the same
records, bit for bit, whatever else the suite holds; wall times are kept apart from them.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from armtransfer.errors import ArmTransferError, InvalidParameterError, InvalidTaskError
from armtransfer.experiments import benchmark_runs, engines, experiment, suites
from armtransfer.learning import methods
from armtransfer.learning import presets
from armtransfer.experiments.learner_trial import reward_methods
from armtransfer.experiments.run import SourceRun, TrialRun
from armtransfer.experiments.stored_form import fill_in, leave_out
from armtransfer.experiments.suite_model import CASE_DEFAULTS
from armtransfer.experiments.comparisons import GOAL_ONLY as GOAL_ONLY, baseline_of as baseline_of
from armtransfer.experiments.comparisons import baselines_of as baselines_of
from armtransfer.experiments.comparisons import registered_baseline as registered_baseline
from armtransfer.learning.learner_names import AT as AT, label as label, parse_label as parse_label
from armtransfer.learning.cells import CELL_METHODS
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.learners import options_of
from armtransfer.tasks.catalog import custom_task, table_task, world_task
from armtransfer.tasks.continuous import continuous_arm
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.tasks.specs import resolve
from armtransfer.tasks.unreachable import hint
from armtransfer.worlds.resolve import world as layout_of

MIN_DISTANCE = 10
"""A drawn task's goal lies at least this many cells (shortest path of the finer robot) from
its start, so no drawn task is trivial."""

DRAWS = 1000
"""Draws of a random task at most before the case is declared impossible."""

SOURCE_CONFIG = LearnerConfig()
"""Robot 1 learns with the learner's defaults (its own step cap), whatever a section caps
robot 2's trials at."""

PLAN_DEFAULTS = {"preset": "default", "learners": None, "quality": SOURCE_CONFIG.quality,
                 "run_on": SOURCE_CONFIG.run_on}
"""The fields a plan's stored spec leaves out at these values (``stored_form``): the default
preset, each section's own learners, the default good-path threshold and run-on budget."""

RECORD_DEFAULTS = {"learner": benchmark_runs.LEARNER}
"""The fields a record leaves out at these values: the built-in learner."""


def learner_methods(learner: str, ran: Sequence[str]) -> list[str]:
    """The methods of ``ran`` that ``learner`` runs: all for the built-in one; ``none`` and the
    reward-term methods for an outside learner (``learner_trial.reward_methods``)."""
    if learner == benchmark_runs.LEARNER:
        return list(ran)
    return reward_methods(list(ran))


CONTROLS_BESIDE = {"plan": ("lazy",)}
"""Controls run beside a baseline wherever it runs: ``lazy`` (``plan`` exploring less, told
nothing) beside ``plan``, so that every report shows whether its clock can be bought by exploring
less (it must not rank ``lazy`` ahead of ``plan``)."""


def methods_to_run(wanted: tuple[str, ...] | None = None) -> tuple[list[str], list[str]]:
    """(the methods to run, in registry order: those of ``wanted`` this build has and every
    baseline they name; those of ``wanted`` this build does not have). ``wanted`` defaults to
    ``suites.METHODS`` and every method of an installed plugin or registered in this process:
    a researcher's method is put through the suite beside the built-in ones; the controls of
    :data:`CONTROLS_BESIDE` run beside their baseline."""
    if wanted is None:
        wanted = (*suites.METHODS, *(m for m in methods.METHODS if m not in methods.BUILTIN))
    chosen: set[str] = set()

    def add(name: str) -> None:
        if name not in chosen:
            chosen.add(name)
            for b in baselines_of(name):
                add(b)
            for c in CONTROLS_BESIDE.get(name, ()):
                if c in methods.METHODS:
                    add(c)

    for m in wanted:
        if m in methods.METHODS:
            add(m)
    return [m for m in methods.METHODS if m in chosen], [m for m in wanted if m not in methods.METHODS]


def section_key(name: str) -> int:
    return zlib.crc32(name.encode())


def run_seed(seed: int, section: str, case: int, source_seed: int) -> int:
    """The seed of one (case, source seed): robot 1's learning and every trial of robot 2."""
    ss = np.random.SeedSequence([int(seed), section_key(section), int(case), int(source_seed)])
    return int(ss.generate_state(1, dtype=np.uint32)[0])


def draw_task(source: DiscreteRobot, target: DiscreteRobot, rng: np.random.Generator,
              distance: tuple[int, int | None] | None = None, cells: str = "any") -> tuple[int, int]:
    """(start cell, goal cell) drawn uniformly over the cells both robots can be placed on and
    reach from the start, anywhere in the world, at least :data:`MIN_DISTANCE` apart, or with
    the finer robot's shortest path in ``distance`` = [low, high) (high None: no limit); start
    and goal on ``cells`` (``suites.CELLS``: even, both coordinates even; odd, not both)."""
    low, high = distance if distance is not None else (MIN_DISTANCE, None)
    common = np.intersect1d(np.unique(source.label), np.unique(target.label))
    common = common[(common >= 0) & (common < source.layout.n_cells)]  # tasks are on the table: level 0 of voxels
    if cells != "any":
        even = np.all(source.layout.xy_of(common) % 2 == 0, axis=-1)
        common = common[even if cells == "even" else ~even]
    for _ in range(DRAWS):
        start = int(rng.choice(common))
        reach = [np.unique(r.label[r.reachable_from(r.start_state(start))]) for r in (source, target)]
        goals = np.intersect1d(np.intersect1d(reach[0], reach[1]), common)
        goals = goals[goals != start]
        if len(goals) == 0:
            continue
        goal = int(rng.choice(goals))
        lengths = [r.shortest_path(r.start_state(start), goal) for r in (source, target)]
        steps = [len(p) - 1 for p in lengths if p is not None]
        if len(steps) == 2 and max(steps) >= low and (high is None or max(steps) < high):
            return start, goal
    band = f"{low}+" if high is None else f"{low}-{high - 1}"
    raise InvalidTaskError(f"no task of {band} steps on {cells} cells that both {source.name} and {target.name} "
                           f"can do in {DRAWS} draws")


@dataclass
class Robots:
    """Robots by spec, each resolved (and, for an arm, compiled or loaded) once per run."""

    resolved: dict
    worlds: dict = field(default_factory=dict)
    """The worlds a suite carries (``Suite.layouts``), by id: a suite file's layout files."""

    def __call__(self, spec: str, world: str = suites.DEFAULT_WORLD) -> DiscreteRobot:
        key = benchmark_runs.robot_key(spec, world)
        if key not in self.resolved:
            if world == suites.DEFAULT_WORLD:
                self.resolved[key] = resolve(spec)
            elif world in self.worlds:
                self.resolved[key] = resolve(spec, layout=self.worlds[world])
            else:
                self.resolved[key] = resolve(spec, layout=layout_of(world))
        return self.resolved[key]


def case_cells(case: suites.Case, source: DiscreteRobot, target: DiscreteRobot, seed: int, section: str,
               index: int, source_seed: int) -> tuple[int, int]:
    if case.start is not None and case.goal is not None:
        return custom_task(case.start, case.goal, target.layout).cells(target.layout)
    if case.task is not None:
        if case.world == suites.DEFAULT_WORLD:
            if isinstance(case.task, bool) or not isinstance(case.task, int):
                raise InvalidTaskError(f"{case.label}: a task of the rooms is a Table I task number")
            return table_task(case.task).cells()
        return world_task(target.layout, case.task).cells()
    rng = np.random.default_rng(np.random.SeedSequence(
        [int(seed), section_key(section), int(index), int(source_seed), 1]))
    return draw_task(source, target, rng, case.distance, case.cells)


class IncompleteError(ArmTransferError):
    """Not every run of a benchmark is in (yet)."""

    def __init__(self, message: str, missing: int) -> None:
        super().__init__(message)
        self.missing = missing


Lookup = Callable[[SourceRun], "dict | None"]
"""A finished run's result by its run (None: not finished)."""


@dataclass(frozen=True)
class Pair:
    """One (section, case, source seed): robot 1 learns its task once, and every method's trials
    follow on robot 2."""

    section: suites.Section
    index: int
    """The case's place in its section."""
    case: suites.Case
    source_seed: int
    seed: int
    """:func:`run_seed`: robot 1's learning and every trial of robot 2."""
    start: tuple[int, int]
    goal: tuple[int, int]
    optimal: int
    """Robot 2's shortest path, in its own steps (a continuous target's: its table robot's, the
    moves it makes without noise)."""
    learner: LearnerConfig = SOURCE_CONFIG
    """Robot 2's learner settings (a preset's; the defaults unless one is named)."""

    @property
    def config(self) -> LearnerConfig:
        """Robot 2's learner: :attr:`learner`, with the section's step cap."""
        return replace(self.learner, max_total_steps=self.section.max_total_steps)

    def source_run(self) -> SourceRun:
        return benchmark_runs.source_run(self.case.source, self.case.target, list(self.start), list(self.goal),
                                         self.seed, SOURCE_CONFIG, world=self.case.world)

    def trial_runs(self, names: Sequence[str], source_result: dict | None,
                   learner: str = benchmark_runs.LEARNER) -> list[TrialRun]:
        """Every trial run of the methods ``names`` by ``learner``, in (method, trial) order;
        without the source run's result, only those of the methods that read no trajectory."""
        options = None
        if learner != benchmark_runs.LEARNER:
            options = options_of(learner)
        return [benchmark_runs.trial_run(name, k, self.case.source, self.case.target, list(self.start),
                                         list(self.goal), self.case.wind, self.seed, self.config, source_result,
                                         learner=learner, world=self.case.world, state=self.case.state,
                                         noise=self.case.noise, learner_options=options)
                for name in names if source_result is not None or not benchmark_runs.needs_trajectory(name)
                for k in range(self.section.trials)]

    def waiting_runs(self, names: Sequence[str], source_result: dict,
                     learner: str = benchmark_runs.LEARNER) -> list[TrialRun]:
        """The trial runs that wait for the source run: those of the methods that read the
        trajectory (the others are in :meth:`trial_runs` without it)."""
        return [run for run in self.trial_runs(names, source_result, learner)
                if benchmark_runs.needs_trajectory(run.method)]

    def base(self, source_result: dict) -> dict:
        """What every record of this pair holds, before its method's."""
        traj = source_result["trajectory"]
        return {"section": self.section.name, "case": self.index, "label": self.case.label,
                "source": self.case.source, "target": self.case.target, "task": self.case.task,
                "start": list(self.start), "goal": list(self.goal), "wind": self.case.wind,
                "source_seed": self.source_seed, "seed": self.seed,
                "source_steps": None if traj is None else len(traj["cells"]),
                "source_failure": source_result["failure"], "optimal": self.optimal,
                "cap": self.section.max_total_steps, "budget": suites.BUDGET_FACTOR * self.optimal,
                **leave_out({"world": self.case.world, "state": self.case.state, "noise": self.case.noise},
                            CASE_DEFAULTS)}


def record(pair: Pair, name: str, source_result: dict, trials: list[dict], ran: Sequence[str] | None = None) -> dict:
    """One record: method ``name``'s trials on ``pair`` (none when it could not run: then
    ``error`` says why, the first trial's in trial order, and every trial counts as a failure);
    its baselines those of ``ran`` (None: all it names)."""
    named = [b for b in baselines_of(name) if ran is None or b in ran]
    rec = dict(pair.base(source_result), method=name, baselines=named, error=None)
    method, learner = parse_label(name)
    if source_result["trajectory"] is None and benchmark_runs.needs_trajectory(method):
        rec["told_nothing"] = benchmark_runs.told_nothing(method)
    rec["learner"] = learner
    n = len(trials)
    errors = [t["error"] for t in trials if t["error"] is not None]
    if errors:
        rec["error"] = errors[0]
        rec.update(first_exposure=[None] * n, converged=[False] * n, convergence_steps=[None] * n,
                   greedy_steps=[None] * n, episodes=[0] * n, area=[None] * n, curves=[],
                   **{name: [None] * n for name in benchmark_runs.CLOCK_FIELDS})
        return leave_out(rec, RECORD_DEFAULTS)
    said = list(dict.fromkeys(w for t in trials for w in t.get("warnings") or ()))
    if said:  # a potential of one's own that was squashed, constant or not 0 at the goal
        rec["warnings"] = said
    rec.update({key: [t[field] for t in trials] for key, field in (
        ("first_exposure", "first_exposure"), ("converged", "converged"), ("convergence_steps", "convergence_steps"),
        ("greedy_steps", "greedy_steps"), ("episodes", "episodes"), ("area", "area"), ("curves", "curve"))})
    rec.update({name: [t.get(name) for t in trials] for name in benchmark_runs.CLOCK_FIELDS})
    notes = sorted({t["clock_note"] for t in trials if t.get("clock_note")})
    if notes:
        rec["clock_note"] = notes[0]
    return leave_out(rec, RECORD_DEFAULTS)


@dataclass(frozen=True)
class Plan:
    """Every run of a suite for one seed, and how their results become the records."""

    suite: suites.Suite
    seed: int
    methods: tuple[str, ...]
    """The methods run, in registry order (:func:`methods_to_run`)."""
    missing: tuple[str, ...]
    """The suite's methods this build's registry does not have."""
    pairs: tuple[Pair, ...]
    preset: str = "default"
    """The learner preset robot 2 learns with (``learning.presets``)."""
    learners: tuple[str, ...] | None = None
    """The learners every method runs on; None: each section's own (``Section.learners``)."""
    quality: float = SOURCE_CONFIG.quality
    """The good path's threshold robot 2's trials run with (``LearnerConfig.quality``)."""
    run_on: float = SOURCE_CONFIG.run_on
    """The run-on budget robot 2's trials run with (``LearnerConfig.run_on``)."""

    @property
    def name(self) -> str:
        return f"benchmark-{self.suite.name}"

    def learners_of(self, pair: Pair) -> tuple[str, ...]:
        return self.learners if self.learners is not None else pair.section.learners

    def entries(self, pair: Pair) -> list[tuple[str, list[str]]]:
        """(learner, the methods it runs) for ``pair``, per learner: of the plan's methods, those
        of the pair's section (``Section.methods``, with their baselines) when it names some."""
        ran = list(self.methods)
        if pair.section.methods is not None:
            keep = methods_to_run(pair.section.methods)[0]
            ran = [m for m in ran if m in keep]
        if pair.case.state != "discrete":  # a continuous target runs the methods paid on labels alone
            ran = [m for m in ran if m == "none" or m in CELL_METHODS]
        return [(lr, learner_methods(lr, ran)) for lr in self.learners_of(pair)]

    def labels(self, pair: Pair | None = None) -> list[str]:
        """The records' names of ``pair`` (None: of every pair, in order): per learner, its methods
        (:func:`label`)."""
        pairs = self.pairs if pair is None else (pair,)
        return list(dict.fromkeys(label(m, lr) for p in pairs for lr, ms in self.entries(p) for m in ms))

    def all_trial_runs(self, pair: Pair, source_result: dict | None) -> list[TrialRun]:
        """Every trial run of ``pair``: per learner, :meth:`Pair.trial_runs` of its methods."""
        return [run for lr, ms in self.entries(pair) for run in pair.trial_runs(ms, source_result, lr)]

    def waiting_runs(self, pair: Pair, source_result: dict) -> list[TrialRun]:
        """The trial runs of ``pair`` that wait for its source run, every learner's."""
        return [run for lr, ms in self.entries(pair) for run in pair.waiting_runs(ms, source_result, lr)]

    def trials_of(self, pair: Pair) -> int:
        """Trial runs of ``pair``, every learner's."""
        return sum(len(ms) for _, ms in self.entries(pair)) * pair.section.trials

    def spec(self) -> dict:
        """What the store holding this plan's runs is for (its key is a hash of it)."""
        spec = {"suite": self.suite.to_dict(), "seed": self.seed, "methods": list(self.methods),
                "not_in_registry": list(self.missing), "formats": list(benchmark_runs.FORMATS),
                "source_config": SOURCE_CONFIG.to_dict(), "preset": self.preset,
                "learners": None if self.learners is None else list(self.learners), "quality": self.quality,
                "run_on": self.run_on}
        return {"benchmark": leave_out(spec, PLAN_DEFAULTS)}

    @staticmethod
    def stored_fields(spec: dict) -> dict:
        """A stored plan's spec (``spec()["benchmark"]``) with every field it leaves out filled in."""
        return fill_in(spec, PLAN_DEFAULTS)

    def size(self) -> int:
        """Runs in all: a source run and every method's trials per pair."""
        return sum(1 + self.trials_of(p) for p in self.pairs)

    def waiting(self, pair: Pair) -> int:
        """Trial runs of ``pair`` that wait for its source run (their methods read the trajectory)."""
        return sum(benchmark_runs.needs_trajectory(m) for _, ms in self.entries(pair) for m in ms) \
            * pair.section.trials

    def records(self, result: Lookup, failed: dict[str, str] | None = None) -> list[dict]:
        """One record per (section, case, source seed, method), in the plan's order, from the
        runs' results; :class:`IncompleteError` when a run's result is not there and it did not
        fail. ``failed``: the runs that failed, by key (their first error line): a record one of
        whose runs failed is left out (the statistics pair records by source seed, so the others
        stay paired) and named in :meth:`failures`."""
        return self._records(result, failed or {})[0]

    def failures(self, result: Lookup, failed: dict[str, str]) -> list[dict]:
        """The records :meth:`records` leaves out because a run of theirs failed: per (section,
        case, source seed, method; ``source`` for robot 1's run) the runs that failed and the
        first error, in the plan's order."""
        return self._records(result, failed)[1]

    def _records(self, result: Lookup, failed: dict[str, str]) -> tuple[list[dict], list[dict]]:
        out, lost, missing = [], [], 0

        def lose(pair: Pair, name: str, keys: list[str]) -> None:
            lost.append({"section": pair.section.name, "case": pair.index, "label": pair.case.label,
                         "source_seed": pair.source_seed, "method": name, "failed_runs": len(keys),
                         "error": failed[keys[0]]})

        for pair in self.pairs:
            src = pair.source_run()
            source = result(src)
            if source is None:
                if src.key() in failed:  # the pair is left out: robot 1's run failed, and any that ran without it
                    lose(pair, "source", [src.key(), *(run.key() for run in self.all_trial_runs(pair, None)
                                                        if run.key() in failed)])
                else:
                    missing += 1 + self.trials_of(pair)
                continue
            trials = [(run, result(run)) for run in self.all_trial_runs(pair, source)]
            missing += sum(r is None and run.key() not in failed for run, r in trials)
            names = self.labels(pair)
            for name in names:
                mine = [(run, r) for run, r in trials if label(run.method, run.learner) == name]
                if all(r is not None for _, r in mine):
                    out.append(record(pair, name, source, [r for _, r in mine if r is not None], names))
                elif keys := [run.key() for run, r in mine if r is None and run.key() in failed]:
                    lose(pair, name, keys)
        if missing:
            raise IncompleteError(f"{missing} of {self.size()} runs are not in yet", missing)
        return out, lost

    def timings(self, result: Lookup, seconds: Callable[[SourceRun], float | None]) -> dict:
        """Each pair's seconds: its source run's and, per method, its trial runs' summed;
        ``total_seconds``: every run's, summed (the work, whichever workers did it)."""
        rows, total = [], 0.0
        for pair in self.pairs:
            src = pair.source_run()
            source_seconds = seconds(src) or 0.0
            per_method: dict[str, float] = {}
            for run in self.all_trial_runs(pair, result(src)):
                name = label(run.method, run.learner)
                per_method[name] = per_method.get(name, 0.0) + (seconds(run) or 0.0)
            total += source_seconds + sum(per_method.values())
            rows.append({"section": pair.section.name, "case": pair.index, "source_seed": pair.source_seed,
                         "source_seconds": round(source_seconds, 3),
                         "methods": {m: round(v, 3) for m, v in per_method.items()}})
        return {"runs": rows, "total_seconds": round(total, 3)}


def plan(suite: suites.Suite, seed: int = 0, robots: Robots | None = None,
         ran: Sequence[str] | None = None, missing: Sequence[str] = (), preset: str = "default",
         learners: Sequence[str] | None = None, quality: float | None = None,
         run_on: float | None = None) -> Plan:
    """Every pair of ``suite`` for ``seed``, its task's cells drawn and checked for both robots
    (an error names the case before anything runs); ``ran``: the methods (default
    :func:`methods_to_run`'s); robot 2 learns with the settings of ``preset`` (robot 1 always
    with the defaults); ``learners``: the learners every method runs on (None: each section's
    own); ``quality``: the good path's threshold (``LearnerConfig.quality``; None: the preset's);
    ``run_on``: the run-on budget (``LearnerConfig.run_on``; None: the preset's)."""
    learner = presets.config(preset)
    if quality is not None:
        learner = replace(learner, quality=quality)  # checked by LearnerConfig: a one-line error
    if run_on is not None:
        learner = replace(learner, run_on=run_on)
    if ran is None:
        ran, missing = methods_to_run()
    robots = robots if robots is not None else Robots({})
    robots.worlds.update(suite.layouts())
    pairs = []
    for section in suite.sections:
        outside = [lr for lr in (section.learners if learners is None else learners) if lr != benchmark_runs.LEARNER]
        for ci, case in enumerate(section.cases):
            for lr in outside:
                engines.engine_for(lr, case.state, f"{case.label} has")
            source, target = robots(case.source, case.world), robots(case.target, case.world)
            arm, placed = None, set()
            if case.state != "discrete":  # a continuous target: its arm, placed over every start before anything runs
                try:  # a bad noise or an arm with no continuous counterpart: the case named
                    arm = continuous_arm(case.target, layout=target.layout, noise=case.noise)
                except ArmTransferError as err:
                    raise InvalidParameterError(f"{case.label}: {err}") from None
            for j in range(section.source_seeds):
                try:
                    start, goal = case_cells(case, source, target, seed, section.name, ci, j)
                    source.start_state(start)
                except ArmTransferError as err:  # the case named, before anything runs
                    raise InvalidTaskError(f"{case.label}: {err}") from None
                if arm is not None and start not in placed:
                    try:
                        arm.place(start)
                    except ArmTransferError as err:  # the case named, before anything runs
                        raise InvalidTaskError(f"{case.label}: {err}") from None
                    placed.add(start)
                path = target.shortest_path(target.start_state(start), goal)
                if path is None:
                    raise InvalidTaskError(f"{case.label}: {target.name} cannot reach the goal{hint(target)}")
                pairs.append(Pair(section, ci, case, j, run_seed(seed, section.name, ci, j), target.layout.xy(start),
                                  target.layout.xy(goal), len(path) - 1, learner))
    return Plan(suite, int(seed), tuple(ran), tuple(missing), tuple(pairs), preset,
                None if learners is None else tuple(learners), learner.quality, learner.run_on)


def run_suite(suite: suites.Suite, seed: int = 0, tick: Callable[[], None] | None = None,
              threads: int | None = None, preset: str = "default",
              learners: Sequence[str] | None = None) -> tuple[list[dict], dict]:
    """Every run of ``suite``, in this process: (records, one per (section, case, source seed,
    method), and the seconds of the runs, kept apart so that the records depend on ``seed``
    alone). A pair's trial runs share ``threads`` threads (None: one per CPU); ``tick`` is
    called once per trial. Robot 2 learns with the settings of ``preset`` (``learning.presets``)."""
    robots = Robots({})
    p = plan(suite, seed, robots, preset=preset, learners=learners)
    results: dict[str, dict] = {}
    seconds: dict[str, float] = {}
    for pair in p.pairs:
        src = pair.source_run()
        results[src.key()], seconds[src.key()] = benchmark_runs.execute(src, robots.resolved)
        runs = p.all_trial_runs(pair, results[src.key()])
        done = experiment.map_trials(lambda i: benchmark_runs.execute(runs[i], robots.resolved), len(runs), threads,
                                     on_trial=tick)
        for run, (result, secs) in zip(runs, done):
            results[run.key()], seconds[run.key()] = result, secs
    found = lambda run: results.get(run.key())  # noqa: E731
    return p.records(found), p.timings(found, lambda run: seconds.get(run.key()))

"""The prediction and the ablation of the ``paper-calibrated`` learner (``learning.presets``).

The preset was fitted to the paper's no-transfer columns only (``research/calibrate.py``). With
it, this module predicts the transfer columns (Table II B-C, Table V B-C: exploration steps with
the pseudo reward, and their improvement over no transfer) over several source seeds, and
ablates the cause of the gap to the paper, every variant against the calibrated no-transfer
baseline on the same trial streams:

  * ``pseudo, safe K``: the calibrated learner with K = 'auto' (verified unfarmable);
  * ``K alone``: the calibrated learner with the paper-like K, chosen before any transfer run as
    the paper describes it, "much smaller than the task's rewards": a tenth of the largest reward
    magnitude (:data:`PAPER_K_FRACTION`). It may be farmable; that is checked (value iteration,
    ``learning.farming``) and reported, and it is run anyway;
  * ``reward structure alone``: the calibrated alpha, gamma, lambda and epsilon with a positive
    goal reward and zero step cost (:data:`POSITIVE_GOAL`), K a tenth of the goal reward;
  * ``exploration alone``: the calibrated rewards and safe K with the default learner's alpha,
    gamma, lambda and epsilon.

Only the first episode enters exploration steps, so these trials stop at the goal
(``max_episodes=1``) and at :data:`STUDY_CAP` steps (a trial that reaches it counts there, and the
mean is then a lower bound). What farming does to learning after the first episode is measured
apart (:func:`farming_runs`): whole trials with the paper-like K, how many converge on a path to
the goal.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import experiment
from armtransfer.experiments.stats import metrics
from armtransfer.experiments.stats.hierarchical import MIN_UNITS
from armtransfer.learning import farming, methods, presets, sarsa
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.tasks.robot import DiscreteRobot

PAPER_K_FRACTION = 0.1
"""The paper-like K as a fraction of the largest reward magnitude: "much smaller than the task's
rewards" read as an order of magnitude smaller. Fixed before any transfer run."""
POSITIVE_GOAL = {"step_reward": 0.0, "goal_reward": 1.0}
"""The reward structure of the ablation: a positive goal, no step cost."""
EXPLORATION = ("alpha", "gamma", "lam", "epsilon")
"""The settings the exploration ablation takes from the default learner."""
STUDY_CAP = 2_000_000
"""Steps of a first episode at most in the study."""
SOURCE_SEEDS = 10
"""Source seeds per cell: the source robot learns each task again per seed. Trials from one seed
share its trajectory, so the improvement's interval resamples seeds (``metrics.seed_improvement``),
which needs at least ``hierarchical.MIN_UNITS`` of them: 3 seeds gave ten distinct resamples."""
FARMING_TRIALS = 10
FARMING_CAP = 1_000_000
"""Whole trials per task of the farming measurement, and their step cap."""
DIRECTIONS = {"table_ii": ("coarse", "fine"), "table_v": ("fine", "coarse")}
TASKS = (1, 2, 3, 4)
VARIANTS = ("none", "pseudo, safe K", "K alone", "reward structure alone", "exploration alone")


def paper_like_k(config: LearnerConfig) -> float:
    """A tenth of the task's largest reward magnitude (step or goal)."""
    scale = max(abs(config.step_reward), abs(config.goal_reward))
    if scale == 0:
        raise InvalidParameterError("the paper-like K needs a non-zero step or goal reward")
    return PAPER_K_FRACTION * scale


def variant_configs(config: LearnerConfig) -> dict[str, tuple[LearnerConfig, float | str | None]]:
    """(learner, K) of every variant; K None: no transfer."""
    default = LearnerConfig()
    rewards = replace(config, step_reward=POSITIVE_GOAL["step_reward"], goal_reward=POSITIVE_GOAL["goal_reward"])
    explore = replace(config, **{k: getattr(default, k) for k in EXPLORATION})
    return {
        "none": (config, None),
        "pseudo, safe K": (config, "auto"),
        "K alone": (config, paper_like_k(config)),
        "reward structure alone": (rewards, paper_like_k(rewards)),
        "exploration alone": (explore, "auto"),
    }


def _pseudo_trials(robot: DiscreteRobot, start: int, goal: int, traj: Trajectory, config: LearnerConfig,
                   K: float | str | None, trials: int, seed: int, tick: Callable[[], None] | None) -> dict:
    """``trials`` trials (None K: no transfer); a farmable K is used as given, not refused."""
    s0 = robot.start_state(start)
    shaping = None
    out: dict = {"K": None, "farmable": None}
    if K is not None:
        k = farming.auto_k(robot, s0, goal, [traj], config) if K == "auto" else float(K)
        build = methods.get("pseudo").build
        assert build is not None
        shaping = build(robot, [traj], k, 0.0)  # the registry's builder: the farming check is left out
        out["K"] = k
        out["farmable"] = (config.step_reward + max(traj.n, 1) * k >= 0
                           or farming.is_farmable(robot, s0, goal, [traj], k, config))
    res = experiment.map_trials(
        lambda t: sarsa.learn(robot, s0, goal, config, experiment.trial_rng(seed, t), shaping=shaping),
        trials, None, tick)
    out["results"] = res
    return out


def run_study(config: LearnerConfig, trials: int, seed: int, tick: Callable[[], None] | None = None) -> dict:
    """The prediction and the ablation, both directions, tasks 1-4; ``trials`` per cell split over
    :data:`SOURCE_SEEDS` source seeds (seed, seed + 1, ...), pooled."""
    per_seed = -(-trials // SOURCE_SEEDS)
    variants = variant_configs(config)
    out: dict = {"trials": per_seed * SOURCE_SEEDS, "source_seeds": [seed + j for j in range(SOURCE_SEEDS)],
                 "cap": STUDY_CAP, "paper_k_fraction": PAPER_K_FRACTION, "positive_goal": POSITIVE_GOAL,
                 "exploration_from_default": {k: getattr(LearnerConfig(), k) for k in EXPLORATION},
                 "variants": list(VARIANTS), "preset": dict(presets.PRESETS[presets.PAPER_CALIBRATED])}
    for key, (src_name, tgt_name) in DIRECTIONS.items():
        src, tgt = grid_robot(src_name), grid_robot(tgt_name)
        table: dict = {}
        for task in TASKS:
            start, goal = TABLE_I[task].cells()
            steps: dict[str, list] = {v: [] for v in VARIANTS}
            by_seed: dict[str, list] = {v: [] for v in VARIANTS}
            ks: dict[str, list] = {v: [] for v in VARIANTS}
            farm: dict[str, list] = {v: [] for v in VARIANTS}
            source_steps = []
            for j in range(SOURCE_SEEDS):
                traj = experiment.source_trajectory("learned", src, start, goal, config, seed + j)
                source_steps.append(len(traj.cells))  # its cells s_t0..s_tn, the goal after them: n + 1 steps
                for name, (cfg, K) in variants.items():
                    cfg = replace(cfg, max_episodes=1, max_total_steps=STUDY_CAP)
                    r = _pseudo_trials(tgt, start, goal, traj, cfg, K, per_seed, seed + j, tick)
                    steps[name] += [t.exploration_steps for t in r["results"]]
                    by_seed[name].append([t.exploration_steps for t in r["results"]])
                    ks[name].append(r["K"])
                    farm[name].append(r["farmable"])
            cell: dict = {}
            for name in VARIANTS:
                entry = metrics.exploration_stats(steps[name], STUDY_CAP)
                entry.update(exploration_steps=steps[name], K=ks[name], farmable=farm[name])
                if name != "none":
                    imp = metrics.seed_improvement(by_seed["none"], by_seed[name], STUDY_CAP, MIN_UNITS)
                    entry.update(improvement_percent=imp["percent"], improvement_ci95=imp["ci95"],
                                 improvement_design=imp["design"], improvement_too_few=imp["too_few"],
                                 exploration_steps_by_seed=by_seed[name])
                else:
                    entry.update(exploration_steps_by_seed=by_seed[name])
                cell[name] = entry
            src_path = src.shortest_path(src.start_state(start), goal)
            cell["source"] = {"steps": source_steps, "shortest": None if src_path is None else len(src_path) - 1}
            table[task] = cell
        out[key] = table
    out["farming"] = farming_runs(config, seed, tick)
    return out


def farming_runs(config: LearnerConfig, seed: int, tick: Callable[[], None] | None = None) -> dict:
    """Whole trials (to convergence or :data:`FARMING_CAP` steps) coarse -> fine with the safe and
    the paper-like K: how many converge on a greedy path to the goal, and in how many steps."""
    src, tgt = grid_robot("coarse"), grid_robot("fine")
    cfg = replace(config, max_total_steps=FARMING_CAP)
    out: dict = {"trials": FARMING_TRIALS, "cap": FARMING_CAP}
    for task in TASKS:
        start, goal = TABLE_I[task].cells()
        traj = experiment.source_trajectory("learned", src, start, goal, config, seed)
        row = {}
        for name, K in (("safe K", "auto"), ("paper-like K", paper_like_k(config))):
            r = _pseudo_trials(tgt, start, goal, traj, cfg, K, FARMING_TRIALS, seed, tick)
            res = r["results"]
            row[name] = {"K": r["K"], "farmable": r["farmable"],
                         "converged": sum(t.converged for t in res),
                         "reached": sum(t.exploration_steps is not None for t in res),
                         "total_steps": [t.total_steps for t in res],
                         "greedy_steps": [t.greedy_steps for t in res]}
        out[task] = row
    return out


def plan(trials: int) -> int:
    """Trials :func:`run_study` runs (for progress bars)."""
    per_seed = -(-trials // SOURCE_SEEDS)
    return len(DIRECTIONS) * len(TASKS) * SOURCE_SEEDS * len(VARIANTS) * per_seed + len(TASKS) * 2 * FARMING_TRIALS

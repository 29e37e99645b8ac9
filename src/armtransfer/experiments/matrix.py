"""The cross-embodiment matrix: which robots help which.

Every ordered (source, target) pair of a set of robots, a robot to itself included, runs
through the sweep store (resumable, local or Ray) with ``none``, each transfer method and the
baselines that share their learners (``Method.baselines``).
The matrix cell of a pair and method is the improvement in exploration steps over ``none``
on the same target, pooled over the tasks:

    improvement = 100 * (1 - sum_tasks mean_method / sum_tasks mean_none)

Each task's mean is over its trials, with a trial that never reached the goal counted at
the step cap (so a method that fails can never look better than it is). The 95% interval
is a percentile bootstrap over trials, resampled within each task and method, from a fixed
seed so the same store always gives the same numbers. Pairs are also grouped by the
robots' families: within a family (interpolation) against across families (extrapolation).
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import sweep as sweeps
from armtransfer.experiments.lazy import pyplot
from armtransfer.experiments.tables import markdown_table
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.learner_names import SARSA, label, parse_label
from armtransfer.learning.methods import with_baselines
from armtransfer.models import ARMS
from armtransfer.tasks.grid_robots import GRID_ROBOTS

BOOTSTRAP = 2000
BOOTSTRAP_SEED = 0


def family(spec: str) -> str:
    """A robot's family, for grouping: ``grid``, ``planar``/``spatial`` (built-in arms, by
    kind), ``gen-FAMILY`` (generated arms), ``custom`` (an arm file)."""
    if spec in GRID_ROBOTS:
        return "grid"
    name = spec.split(":")[0]
    if name in ARMS:
        return ARMS[name].kind
    if name.startswith("gen"):
        parts = spec.split(":")
        return f"gen-{parts[1]}" if len(parts) > 1 and parts[0] == "gen" else "gen"
    return "custom"


def matrix_spec(robots: Sequence[str], tasks: Sequence[int | str], methods: Sequence[str], trials: int,
                seeds: Sequence[int] = (0,), trajectory: str = "learned", name: str = "matrix",
                arms: dict | None = None, world: str | None = None, preset: str = "default",
                learners: Sequence[str] = (SARSA,), max_total_steps: int | None = None) -> dict:
    """The sweep of every ordered pair of ``robots`` (each robot to itself too); ``arms`` names
    bring-your-own arms as a sweep file's ``[arms.NAME]`` tables do (``NAME[:ACTIONS]`` robots);
    ``world`` is the sweep's world (the paper's rooms when None); ``preset`` the learner's
    settings (``learning.presets``); ``learners`` who learns on the targets (a sweep's
    ``learner``: each runs every method, beside the ``none`` it runs); ``max_total_steps`` the
    steps a trial at most (None: the preset's)."""
    robots = list(robots)
    if len(robots) < 2:
        raise InvalidParameterError("a matrix needs at least two robots")
    if len(set(robots)) != len(robots):
        raise InvalidParameterError("a matrix lists each robot once")
    methods = with_baselines(["none", *methods])
    if len(methods) < 2:
        raise InvalidParameterError("a matrix needs a transfer method beside 'none'")
    body = {"name": name, "tasks": list(tasks), "pairs": [[s, t] for s in robots for t in robots],
            "methods": methods, "seeds": list(seeds), "trials": trials, "trajectory": trajectory, "preset": preset,
            "learner": list(learners)}
    given = {"world": world, "max_total_steps": max_total_steps}  # None: not given (the sweep's default)
    body.update({key: value for key, value in given.items() if value is not None})
    return sweeps.normalise({"sweep": body, "arms": arms or {}}, where="matrix")


def matrix_sweep(robots: Sequence[str], tasks: Sequence[int | str], methods: Sequence[str], trials: int,
                 seeds: Sequence[int] = (0,), trajectory: str = "learned", name: str = "matrix",
                 arms: dict | None = None, world: str | None = None, preset: str = "default",
                 learners: Sequence[str] = (SARSA,), max_total_steps: int | None = None) -> sweeps.Sweep:
    spec = matrix_spec(robots, tasks, methods, trials, seeds, trajectory, name, arms, world, preset, learners,
                       max_total_steps)
    return sweeps.Sweep(spec["name"], spec, tuple(sweeps.expand(spec)))


@dataclass(frozen=True)
class Cell:
    source: str
    target: str
    method: str
    improvement: float | None
    ci95: tuple[float, float] | None
    tasks: int
    """Tasks with both ``none`` and this method finished (the pooled sum runs over these)."""
    reached: int
    trials: int


def _steps(values: list, cap: int) -> np.ndarray:
    return np.array([cap if v is None else v for v in values], dtype=float)


def cells(records: list[dict], cap: int = LearnerConfig().max_total_steps) -> list[Cell]:
    """Every (source, target, method) cell of the finished runs in a store (a trial that never
    reached the goal counts at its run's ``max_total_steps``, ``cap`` when the run names none)."""
    by: dict[tuple, dict] = {}
    for rec in records:
        cfg = rec["config"]
        task = (cfg["task"], tuple(cfg["start"]), tuple(cfg["goal"]))
        key = (cfg["source"], cfg["target"], label(cfg["method"], cfg.get("learner", SARSA)), task)
        entry = by.setdefault(key, {"steps": [], "cap": int(cfg.get("max_total_steps", cap))})
        entry["steps"].extend(rec["result"]["exploration_steps"])
    rng = np.random.default_rng(BOOTSTRAP_SEED)
    out = []
    combos = sorted({(s, t, m) for s, t, m, _ in by if parse_label(m)[0] != "none"})
    for source, target, method in combos:
        none = label("none", parse_label(method)[1])
        tasks = sorted({k[3] for k in by if k[:3] == (source, target, method)
                        and (source, target, none, k[3]) in by}, key=repr)
        if not tasks:
            out.append(Cell(source, target, method, None, None, 0, 0, 0))
            continue
        base = [_steps(by[(source, target, none, t)]["steps"], by[(source, target, none, t)]["cap"]) for t in tasks]
        meth = [_steps(by[(source, target, method, t)]["steps"], by[(source, target, method, t)]["cap"])
                for t in tasks]
        raw = [by[(source, target, method, t)]["steps"] for t in tasks]
        imp = 100.0 * (1.0 - sum(m.mean() for m in meth) / sum(b.mean() for b in base))
        boots = np.empty(BOOTSTRAP)
        for k in range(BOOTSTRAP):
            num = sum(m[rng.integers(0, len(m), len(m))].mean() for m in meth)
            den = sum(b[rng.integers(0, len(b), len(b))].mean() for b in base)
            boots[k] = 100.0 * (1.0 - num / den)
        lo, hi = np.percentile(boots, [2.5, 97.5])
        n = sum(len(r) for r in raw)
        out.append(Cell(source, target, method, float(imp), (float(lo), float(hi)), len(tasks),
                        sum(v is not None for r in raw for v in r), n))
    return out


def _fmt(c: Cell | None) -> str:
    if c is None or c.improvement is None or c.ci95 is None:
        return "—"
    text = f"{round(c.improvement):d}% [{round(c.ci95[0]):d}, {round(c.ci95[1]):d}]"
    return text if c.reached == c.trials else f"{text} ({c.reached}/{c.trials} reached)"


def family_rows(all_cells: list[Cell]) -> list[dict]:
    """Per method and group (a robot to itself, within a family: interpolation, across
    families: extrapolation): how many pairs, the median improvement (a mean would be ruled by
    the few pairs where transfer fails badly), and how many pairs transfer helped or hurt with
    95% confidence (CI above or below 0)."""
    rows = []
    for method in sorted({c.method for c in all_cells}):
        # each pair's improvement and its CI
        groups: dict[str, list[tuple[float, tuple[float, float]]]] = {
            "self": [], "within family": [], "across families": []}
        for c in all_cells:
            if c.method != method or c.improvement is None or c.ci95 is None:
                continue
            if c.source == c.target:
                group = "self"
            elif family(c.source) == family(c.target):
                group = "within family"
            else:
                group = "across families"
            groups[group].append((c.improvement, c.ci95))
        for name, members in groups.items():
            values = [imp for imp, _ in members]
            rows.append({"method": method, "group": name, "pairs": len(members),
                         "median_improvement": float(np.median(values)) if values else None,
                         "helped": sum(ci[0] > 0 for _, ci in members),
                         "hurt": sum(ci[1] < 0 for _, ci in members)})
    return rows


def markdown(all_cells: list[Cell], robots: list[str]) -> str:
    """One table per method: source rows, target columns, improvement [95% CI]."""
    parts = []
    for method in sorted({c.method for c in all_cells}):
        at = {(c.source, c.target): c for c in all_cells if c.method == method}
        rows = [[s, *(_fmt(at.get((s, t))) for t in robots)] for s in robots]
        none = label("none", parse_label(method)[1])
        parts.append(f"### {method}: improvement over no transfer{f' ({none})' if none != 'none' else ''} (source rows, "
                     "target columns)\n\n"
                     + markdown_table(["source \\ target", *robots], rows))
    fam = family_rows(all_cells)
    parts.append("### By family: interpolation (within a family) against extrapolation (across)\n\n"
                 + markdown_table(["method", "group", "pairs", "median improvement", "helped (CI > 0)",
                                   "hurt (CI < 0)"],
                                  [[r["method"], r["group"], str(r["pairs"]),
                                    "—" if r["median_improvement"] is None else f"{round(r['median_improvement']):d}%",
                                    str(r["helped"]), str(r["hurt"])] for r in fam]))
    return "\n\n".join(parts)


def heatmap_png(all_cells: list[Cell], robots: list[str]) -> bytes:
    """The heatmaps (one panel per method) as PNG bytes."""
    plt = pyplot()
    methods = sorted({c.method for c in all_cells})
    n = len(robots)
    fig, axes = plt.subplots(1, len(methods), figsize=(1.1 * n * len(methods) + 2, 1.0 * n + 2), squeeze=False)
    for ax, method in zip(axes[0], methods):
        grid = np.full((n, n), np.nan)
        for c in all_cells:
            if c.method == method and c.improvement is not None:
                grid[robots.index(c.source), robots.index(c.target)] = c.improvement
        im = ax.imshow(grid, cmap="RdYlGn", vmin=-100, vmax=100)
        for i in range(n):
            for j in range(n):
                if not np.isnan(grid[i, j]):
                    ax.text(j, i, f"{grid[i, j]:.0f}", ha="center", va="center", fontsize=7)
        ax.set_xticks(range(n), robots, rotation=60, ha="right", fontsize=7)
        ax.set_yticks(range(n), robots, fontsize=7)
        ax.set_xlabel("target")
        ax.set_ylabel("source")
        ax.set_title(f"{method}: improvement % over none")
        fig.colorbar(im, ax=ax, shrink=0.7)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


def is_matrix(spec: dict) -> bool:
    """A sweep spec is a matrix when its pairs are every ordered pair of its robots."""
    pairs = [tuple(p) for p in spec.get("pairs", [])]
    robots = list(dict.fromkeys(s for p in pairs for s in p))
    return len(robots) >= 2 and sorted(pairs) == sorted((s, t) for s in robots for t in robots)

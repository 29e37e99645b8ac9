"""Figures: bar charts with 95% error bars (Fig. 4-6 analogs) and learning curves."""

from __future__ import annotations

import io
import os

import numpy as np

from armtransfer.experiments.lazy import pyplot
from armtransfer.experiments.stats.learning_metrics import curve
from armtransfer.io import write_bytes_atomic


def _save(fig, path: str | os.PathLike) -> None:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    pyplot().close(fig)
    write_bytes_atomic(path, buf.getvalue())


def bar_chart(
    groups: list[str],
    series: dict[str, tuple[list[float | None], list[list[float] | None]]],
    title: str,
    ylabel: str,
    path: str | os.PathLike,
    log: bool = False,
    lower_bound: dict[str, list[bool]] | None = None,
) -> None:
    """Grouped bars: ``series`` maps a label to (means per group, 95% CIs per group).
    ``lower_bound[label][g]``: that mean counts unreached trials at the step cap and is a
    lower bound; its bar is hatched and the title says so."""
    fig, ax = pyplot().subplots(figsize=(7 if len(series) < 4 else 9, 4))
    n = len(series)
    width = 0.8 / max(n, 1)
    x = np.arange(len(groups))
    for k, (label, (means, cis)) in enumerate(series.items()):
        m = np.array([np.nan if v is None else v for v in means], dtype=float)
        lo = np.array([np.nan if c is None else v - c[0] for v, c in zip(m, cis)])
        hi = np.array([np.nan if c is None else c[1] - v for v, c in zip(m, cis)])
        bars = ax.bar(x + (k - (n - 1) / 2) * width, m, width, yerr=np.vstack([lo, hi]), capsize=3, label=label)
        for bar, flag in zip(bars, (lower_bound or {}).get(label, [])):
            if flag:
                bar.set_hatch("//")
    ax.set_xticks(x, groups)
    if log:
        ax.set_yscale("log")
    ax.set_ylabel(ylabel)
    if any(any(v) for v in (lower_bound or {}).values()):
        title += "\nhatched: some trials never reached the goal; mean is a lower bound"
    ax.set_title(title)
    ax.legend()
    ax.grid(axis="y", alpha=0.3)
    _save(fig, path)


def learning_curves(
    curves: dict[str, list[list[int]]], title: str, path: str | os.PathLike, max_episodes: int = 200,
    greedy: dict[str, list[int | None]] | None = None,
) -> None:
    """Steps per episode on a log scale: the mean over ALL trials, and a band holding the middle
    half of the trials (their 25th to 75th percentile at each episode).

    The band comes from the trials' own quantiles, so on the log axis it never leaves the range
    of the steps observed (a symmetric interval around the mean would reach below one step).
    Every trial contributes to every episode, by ``learning_metrics.curve`` (the one
    definition the transfer metrics use too): after its last episode a converged trial
    counts its greedy path length (``greedy[label][i]``), an unconverged one its last
    episode. Without ``greedy`` a converged trial also counts its last episode. So late
    episodes are not an average of the slow trials only (no survivorship bias)."""
    fig, ax = pyplot().subplots(figsize=(7, 4))
    for label, trials in curves.items():
        mean, low, high = curve_band(trials, (greedy or {}).get(label), max_episodes)
        eps = np.arange(1, len(mean) + 1)
        ax.plot(eps, mean, label=f"{label} (mean of {len(trials)})")
        ax.fill_between(eps, low, high, alpha=0.25)
    ax.set_yscale("log")
    ax.set_xlabel("episode")
    ax.set_ylabel("steps per episode\n(line: mean of all trials; band: middle half)")
    ax.set_title(title)
    ax.legend()
    ax.grid(alpha=0.3)
    _save(fig, path)


def curve_band(trials: list[list[int]], greedy: list[int | None] | None = None,
               max_episodes: int = 200) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(mean, 25th percentile, 75th percentile) per episode of the curves
    :func:`learning_curves` draws for one label."""
    arr = _matrix(trials, greedy, max_episodes)
    low, high = np.percentile(arr, [25, 75], axis=0)
    return arr.mean(axis=0), low, high


def curve_means(curves: dict[str, list[list[int]]], greedy: dict[str, list[int | None]] | None = None,
                max_episodes: int = 200) -> dict[str, np.ndarray]:
    """The mean curve per label that :func:`learning_curves` draws (for tests and reports)."""
    return {label: _matrix(trials, (greedy or {}).get(label), max_episodes).mean(axis=0)
            for label, trials in curves.items()}


def _matrix(trials: list[list[int]], greedy: list[int | None] | None, max_episodes: int) -> np.ndarray:
    """[trials, episodes]: every trial's ``learning_metrics.curve`` over the longest trial's
    episodes (at most ``max_episodes``)."""
    n = min(max_episodes, max(len(t) for t in trials))
    g = greedy or [None] * len(trials)
    return np.array([curve(t, gi, n) for t, gi in zip(trials, g)])


def mapping_paths(
    wall_mask: np.ndarray,
    lo: int,
    source_cells: list[list[int]],
    target_cells: list[list[int]],
    segments: list[list[int]],
    title: str,
    path: str | os.PathLike,
) -> None:
    """Fig. 7 analog: the rooms map, the source robot's trajectory (dashed), the target's
    greedy path (solid) and the target's mapped fragments (thick). ``segments`` are
    [j0, j1) step ranges of the target path."""
    fig, ax = pyplot().subplots(figsize=(6.5, 6.5))
    hi = lo + wall_mask.shape[0] - 1
    ax.imshow(wall_mask, origin="lower", cmap="Greys", extent=(lo - 0.5, hi + 0.5, lo - 0.5, hi + 0.5),
              vmin=0, vmax=1.4)
    src = np.asarray(source_cells, dtype=float)
    tgt = np.asarray(target_cells, dtype=float)
    ax.plot(src[:, 0], src[:, 1], "--o", color="tab:blue", ms=3, lw=1.2, label="source trajectory")
    ax.plot(tgt[:, 0], tgt[:, 1], "-", color="tab:orange", lw=1.2, label="target greedy path")
    for k, (j0, j1) in enumerate(segments):
        seg = tgt[j0 : j1 + 1]
        ax.plot(seg[:, 0], seg[:, 1], "-", color="tab:red", lw=4, alpha=0.6,
                label="mapped fragment" if k == 0 else None)
    ax.plot(*src[0], "s", color="green", ms=8, label="start")
    ax.plot(*src[-1], "*", color="black", ms=12, label="goal")
    _finish_map(fig, ax, lo, hi, title, 8, path)


def _finish_map(fig, ax, lo: int, hi: int, title: str, legend_size: int, path: str | os.PathLike) -> None:
    """Square axes on the cells lo..hi, the title and the legend, then save."""
    ax.set_xlim(lo - 0.5, hi + 0.5)
    ax.set_ylim(lo - 0.5, hi + 0.5)
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.legend(loc="lower right", fontsize=legend_size)
    _save(fig, path)


def task_layout(
    wall_mask: np.ndarray,
    lo: int,
    tasks: list[tuple[str, tuple[int, int], tuple[int, int]]],
    title: str,
    path: str | os.PathLike,
) -> None:
    """Fig. 3 analog: the rooms map with each task's start (square) and goal (star)."""
    fig, ax = pyplot().subplots(figsize=(6.5, 6.5))
    hi = lo + wall_mask.shape[0] - 1
    ax.imshow(wall_mask, origin="lower", cmap="Greys", extent=(lo - 0.5, hi + 0.5, lo - 0.5, hi + 0.5),
              vmin=0, vmax=1.4)
    colors = pyplot().rcParams["axes.prop_cycle"].by_key()["color"]
    for k, (name, start, goal) in enumerate(tasks):
        c = colors[k % len(colors)]
        ax.plot(*start, "s", color=c, ms=9, label=f"{name}: start {start}")
        ax.plot(*goal, "*", color=c, ms=14, label=f"{name}: goal {goal}")
        ax.annotate(name.split()[-1], start, textcoords="offset points", xytext=(5, 5), color=c)
        ax.annotate(name.split()[-1], goal, textcoords="offset points", xytext=(5, 5), color=c)
    _finish_map(fig, ax, lo, hi, title, 7, path)


def _panel_grid(panels: list, title: str, path: str | os.PathLike, xlabel: str, ylabel: str, draw) -> None:
    """One panel per (label, curves) of ``panels``, four to a row; ``draw(ax, curves)`` plots a
    panel's curves, each labelled by its method; the legend is on the first panel."""
    n = len(panels)
    cols = min(n, 4)
    rows = (n + cols - 1) // cols
    fig, axes = pyplot().subplots(rows, cols, figsize=(4 * cols, 3.2 * rows), squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    for ax, (label, curves) in zip(axes.flat, panels):
        draw(ax, curves)
        ax.set_title(label, fontsize=8)
        ax.set_xlabel(xlabel, fontsize=8)
        ax.set_ylabel(ylabel, fontsize=8)
        ax.grid(alpha=0.3)
    axes.flat[0].legend(fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    _save(fig, path)


def survival_grid(panels: list[tuple[str, dict[str, tuple[list[float], list[float]]]]], cap: float, title: str,
                  path: str | os.PathLike) -> None:
    """Kaplan-Meier curves, one panel per case: ``panels`` is [(case label, {method: (times,
    survival)})]; a curve is the share of trials that have not yet reached the goal after so many
    steps, drawn as a step function up to the cap (where the unreached trials were censored)."""

    def draw(ax, curves):
        for method, (times, surv) in curves.items():
            ax.step([1.0, *times, cap], [1.0, *surv, surv[-1] if surv else 1.0], where="post", label=method)
        ax.set_xscale("log")
        ax.set_ylim(-0.02, 1.02)

    _panel_grid(panels, title, path, "steps of the first episode", "share not yet at the goal", draw)


def curve_grid(panels: list[tuple[str, dict[str, list[float]]]], title: str, path: str | os.PathLike) -> None:
    """Mean learning curves (steps per episode, log scale), one panel per case: ``panels`` is
    [(case label, {method: mean steps per episode})]."""

    def draw(ax, curves):
        for method, mean in curves.items():
            if mean:
                ax.plot(np.arange(1, len(mean) + 1), mean, label=method)
        ax.set_yscale("log")

    _panel_grid(panels, title, path, "episode", "mean steps per episode", draw)

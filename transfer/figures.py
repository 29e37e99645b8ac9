"""Figures: bar charts with 95% error bars (Fig. 4-6 analogs) and learning curves."""

from __future__ import annotations

import os
import warnings

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from armtransfer.io import write_bytes_atomic  # noqa: E402


def _save(fig, path: str | os.PathLike) -> None:
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    write_bytes_atomic(path, buf.getvalue())


def bar_chart(
    groups: list[str],
    series: dict[str, tuple[list[float | None], list[list[float] | None]]],
    title: str,
    ylabel: str,
    path: str | os.PathLike,
    log: bool = False,
) -> None:
    """Grouped bars: ``series`` maps a label to (means per group, 95% CIs per group)."""
    fig, ax = plt.subplots(figsize=(7 if len(series) < 4 else 9, 4))
    n = len(series)
    width = 0.8 / max(n, 1)
    x = np.arange(len(groups))
    for k, (label, (means, cis)) in enumerate(series.items()):
        m = np.array([np.nan if v is None else v for v in means], dtype=float)
        lo = np.array([np.nan if c is None else v - c[0] for v, c in zip(m, cis)])
        hi = np.array([np.nan if c is None else c[1] - v for v, c in zip(m, cis)])
        ax.bar(x + (k - (n - 1) / 2) * width, m, width, yerr=np.vstack([lo, hi]), capsize=3, label=label)
    ax.set_xticks(x, groups)
    if log:
        ax.set_yscale("log")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend()
    ax.grid(axis="y", alpha=0.3)
    _save(fig, path)


def learning_curves(
    curves: dict[str, list[list[int]]], title: str, path: str | os.PathLike, max_episodes: int = 200
) -> None:
    """Steps per episode: the mean over trials and its 95% confidence band, log scale.

    A trial that has converged stops contributing after its last episode."""
    from armtransfer.learning.metrics import t95

    fig, ax = plt.subplots(figsize=(7, 4))
    for label, trials in curves.items():
        n = min(max_episodes, max(len(t) for t in trials))
        arr = np.full((len(trials), n), np.nan)
        for i, t in enumerate(trials):
            t = np.abs(np.asarray(t[:n], dtype=float))
            arr[i, : len(t)] = t
        eps = np.arange(1, n + 1)
        count = np.sum(~np.isnan(arr), axis=0)
        mean = np.nanmean(arr, axis=0)
        with warnings.catch_warnings():  # an episode only one trial reached has no spread
            warnings.simplefilter("ignore", RuntimeWarning)
            sd = np.nan_to_num(np.nanstd(arr, axis=0, ddof=1)) if len(trials) > 1 else np.zeros(n)
        half = np.array([t95(int(c) - 1) * s / np.sqrt(c) if c > 1 else 0.0 for c, s in zip(count, sd)])
        ax.plot(eps, mean, label=f"{label} (mean of {len(trials)})")
        ax.fill_between(eps, np.maximum(mean - half, 1.0), mean + half, alpha=0.25)
    ax.set_yscale("log")
    ax.set_xlabel("episode")
    ax.set_ylabel("steps per episode (mean, 95% CI)")
    ax.set_title(title)
    ax.legend()
    ax.grid(alpha=0.3)
    _save(fig, path)


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
    fig, ax = plt.subplots(figsize=(6.5, 6.5))
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
    ax.set_xlim(lo - 0.5, hi + 0.5)
    ax.set_ylim(lo - 0.5, hi + 0.5)
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.legend(loc="lower right", fontsize=8)
    _save(fig, path)

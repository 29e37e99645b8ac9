"""Figures: bar charts with 95% error bars (Fig. 4-6 analogs) and learning curves."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from transfer.io import write_bytes_atomic  # noqa: E402


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
) -> None:
    """Grouped bars: ``series`` maps a label to (means per group, 95% CIs per group)."""
    fig, ax = plt.subplots(figsize=(7, 4))
    n = len(series)
    width = 0.8 / max(n, 1)
    x = np.arange(len(groups))
    for k, (label, (means, cis)) in enumerate(series.items()):
        m = np.array([np.nan if v is None else v for v in means], dtype=float)
        lo = np.array([np.nan if c is None else v - c[0] for v, c in zip(m, cis)])
        hi = np.array([np.nan if c is None else c[1] - v for v, c in zip(m, cis)])
        ax.bar(x + (k - (n - 1) / 2) * width, m, width, yerr=np.vstack([lo, hi]), capsize=3, label=label)
    ax.set_xticks(x, groups)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend()
    ax.grid(axis="y", alpha=0.3)
    _save(fig, path)


def learning_curves(
    curves: dict[str, list[list[int]]], title: str, path: str | os.PathLike, max_episodes: int = 200
) -> None:
    """Steps per episode: the median over trials and the band between quartiles, log scale."""
    fig, ax = plt.subplots(figsize=(7, 4))
    for label, trials in curves.items():
        n = min(max_episodes, max(len(t) for t in trials))
        arr = np.full((len(trials), n), np.nan)
        for i, t in enumerate(trials):
            t = np.abs(np.asarray(t[:n], dtype=float))
            arr[i, : len(t)] = t
        eps = np.arange(1, n + 1)
        ax.plot(eps, np.nanmedian(arr, axis=0), label=label)
        ax.fill_between(eps, np.nanpercentile(arr, 25, axis=0), np.nanpercentile(arr, 75, axis=0), alpha=0.25)
    ax.set_yscale("log")
    ax.set_xlabel("episode")
    ax.set_ylabel("steps per episode")
    ax.set_title(title)
    ax.legend()
    ax.grid(alpha=0.3)
    _save(fig, path)

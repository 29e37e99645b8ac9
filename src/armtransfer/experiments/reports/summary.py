"""Summaries of a sweep's store: one row per group and method, pooled over seeds.

A group is every run that shares task, robots and parameters (see ``sweep.group_key``);
within it each method (with its K) is a column whose trials are pooled over seeds. The
rows are sorted, so a resumed sweep and an uninterrupted one give the same summary.

Exploration steps count every trial: one that never reached the goal counts at the step
cap (``max_total_steps`` of the run, the learner's default when the run does not say), and
the mean is then flagged as a lower bound (``metrics.exploration_stats``). Improvements pair
trial i of seed s of a method with trial i of seed s of ``none`` (the same random stream).
"""

from __future__ import annotations

from armtransfer.experiments.reports.figures import bar_chart
from armtransfer.experiments.tables import (CAP_NOTE, fmt_ci, fmt_improvement, fmt_mean, fmt_num, markdown_table,
                                          median_column)
from armtransfer.experiments.stats import metrics
from armtransfer.experiments.sweep import group_key
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.learner_names import SARSA, label, parse_label


def _learned(method: str, cfg: dict) -> str:
    """``method`` as a run of ``cfg``'s learner is labelled (``pseudo``; ``pseudo@tabular-q``)."""
    return label(method, cfg.get("learner", SARSA))


def _method_label(cfg: dict) -> str:
    """``pseudo``, ``pseudo (K=0.1)``; ``pseudo@tabular-q`` for an outside learner's run."""
    method = _learned(cfg["method"], cfg)
    return method if cfg["K"] in (None, "auto") else f"{method} (K={cfg['K']})"


def summarize(records: list[dict]) -> list[dict]:
    groups: dict[tuple, dict[str, dict]] = {}
    for rec in records:
        cfg = rec["config"]
        cols = groups.setdefault(group_key(cfg), {})
        col = cols.setdefault(_method_label(cfg), {"config": cfg, "seeds": [], "exploration_steps": [],
                                                    "greedy_steps": [], "total_steps": [], "converged": [],
                                                    "by_seed": {}})
        col["seeds"].append(cfg["seed"])
        col["by_seed"][cfg["seed"]] = list(rec["result"]["exploration_steps"])
        for field in ("exploration_steps", "greedy_steps", "total_steps", "converged"):
            col[field].extend(rec["result"][field])
    rows = []
    for gk in sorted(groups, key=repr):
        cols = groups[gk]
        for label in sorted(cols, key=lambda m: (m != "none", m)):
            col = cols[label]
            cfg = col["config"]
            baseline = _learned("none", cfg)  # the none its learner ran
            base = cols.get(baseline)
            cap = int(cfg.get("max_total_steps", LearnerConfig.max_total_steps))
            st = metrics.exploration_stats(col["exploration_steps"], cap)
            row = {
                "task": cfg["task"],
                "start": cfg["start"],
                "goal": cfg["goal"],
                "source": cfg["source"],
                "target": cfg["target"],
                "wind": cfg["wind"],
                "epsilon": cfg["epsilon"],
                "lam": cfg["lam"],
                "alpha": cfg["alpha"],
                "gamma": cfg["gamma"],
                "method": label,
                "seeds": sorted(col["seeds"]),
                "trials": len(col["exploration_steps"]),
                "reached": st["reached"],
                "mean": st["mean"],
                "ci95": st["ci95"],
                "mean_is_lower_bound": st["mean_is_lower_bound"],
                "median": st["median"],
                "median_ci95": st["median_ci95"],
                "median_ci_coverage": st["median_ci_coverage"],
                "median_is_lower_bound": st["median_is_lower_bound"],
                "greedy_mean": metrics.mean_ci(col["greedy_steps"])[0],
                "total_mean": metrics.mean_ci(col["total_steps"])[0],
                "converged": sum(bool(c) for c in col["converged"]),
                "improvement_percent": None,
                "improvement_ci95": None,
                "improvement_design": None,
                "improvement_censored": None,
                "improvement_cap_dominated": None,
                "mean_cap_dominated": st["cap_dominated"],
            }
            if base is not None and label != baseline:
                imp = _improvement(base, col, cap)
                row["improvement_percent"] = imp["percent"]
                row["improvement_ci95"] = imp["ci95"]
                row["improvement_design"] = imp["design"]
                row["improvement_censored"] = imp["censored"]
                row["improvement_cap_dominated"] = imp["cap_dominated"]
            rows.append(row)
    return rows


def _improvement(base: dict, col: dict, cap: int) -> dict:
    """Paired over the (seed, trial) both columns have with equal trial counts; independent
    samples when no seed pairs up."""
    seeds = sorted(set(base["by_seed"]) & set(col["by_seed"]), key=repr)
    seeds = [s for s in seeds if len(base["by_seed"][s]) == len(col["by_seed"][s])]
    if seeds:
        b = [v for s in seeds for v in base["by_seed"][s]]
        o = [v for s in seeds for v in col["by_seed"][s]]
        return metrics.paired_improvement(b, o, cap, paired=True)
    return metrics.paired_improvement(base["exploration_steps"], col["exploration_steps"], cap, paired=False)


def _task_name(row: dict) -> str:
    if row["task"] is not None:
        return f"task {row['task']}"
    return f"({row['start'][0]},{row['start'][1]})->({row['goal'][0]},{row['goal'][1]})"


def summary_markdown(rows: list[dict]) -> str:
    median_header, median_cell = median_column(rows)
    header = ["task", "source -> target", "wind", "eps", "lambda", "method", "reached goal",
              "mean exploration steps [95% CI]", median_header, "mean improvement % [95% CI]", "mean greedy steps",
              "converged"]
    body = [[
        _task_name(r), f"{r['source']} -> {r['target']}", f"{r['wind']:g}", f"{r['epsilon']:g}", f"{r['lam']:g}",
        r["method"], f"{r['reached']}/{r['trials']}", f"{fmt_mean(r)} {fmt_ci(r['ci95'])}",
        median_cell(r),
        "" if parse_label(r["method"])[0] == "none" else f"{fmt_improvement(r)} {fmt_ci(r['improvement_ci95'])}",
        fmt_num(r["greedy_mean"]), f"{r['converged']}/{r['trials']}",
    ] for r in rows]
    table = markdown_table(header, body)
    if any(r["mean_is_lower_bound"] for r in rows):
        table += "\n\n≥: some trials never reached the goal; they count at the step cap, so the mean is a lower bound."
    if any(r.get("improvement_cap_dominated") for r in rows):
        table += "\n\n" + CAP_NOTE
    designs = sorted({r["improvement_design"] for r in rows} - {None})
    if designs:
        table += "\n\nImprovement CIs: " + "; ".join(designs) + "."
    return table


def plot(rows: list[dict], path) -> None:
    groups: list[str] = []
    series: dict[str, dict[str, tuple]] = {}
    for r in rows:
        g = f"{_task_name(r)}\n{r['source']}->{r['target']}" + (f"\nwind {r['wind']:g}" if r["wind"] else "")
        if g not in groups:
            groups.append(g)
        series.setdefault(r["method"], {})[g] = (r["mean"], r["ci95"], r["mean_is_lower_bound"])
    data = {m: ([v.get(g, (None, None, False))[0] for g in groups], [v.get(g, (None, None, False))[1] for g in groups])
            for m, v in series.items()}
    lower = {m: [v.get(g, (None, None, False))[2] for g in groups] for m, v in series.items()}
    bar_chart(groups, data, "exploration steps to the goal, unreached trials at the step cap (95% CI)",
              "steps", path, lower_bound=lower)

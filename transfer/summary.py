"""Summaries of a sweep's store: one row per group and method, pooled over seeds.

A group is every run that shares task, robots and parameters (see ``sweep.group_key``);
within it each method (with its K) is a column whose trials are pooled over seeds. The
rows are sorted, so a resumed sweep and an uninterrupted one give the same summary.
"""

from __future__ import annotations

from armtransfer.learning import metrics
from armtransfer.learning.report import fmt_ci, fmt_num, markdown_table
from armtransfer.learning.sweep import group_key


def _method_label(cfg: dict) -> str:
    return cfg["method"] if cfg["K"] in (None, "auto") else f"{cfg['method']} (K={cfg['K']})"


def summarize(records: list[dict]) -> list[dict]:
    groups: dict[tuple, dict[str, dict]] = {}
    for rec in records:
        cfg = rec["config"]
        cols = groups.setdefault(group_key(cfg), {})
        col = cols.setdefault(_method_label(cfg), {"config": cfg, "seeds": [], "exploration_steps": [],
                                                    "greedy_steps": [], "total_steps": [], "converged": []})
        col["seeds"].append(cfg["seed"])
        for field in ("exploration_steps", "greedy_steps", "total_steps", "converged"):
            col[field].extend(rec["result"][field])
    rows = []
    for gk in sorted(groups, key=repr):
        cols = groups[gk]
        base = cols.get("none")
        for label in sorted(cols, key=lambda m: (m != "none", m)):
            col = cols[label]
            cfg = col["config"]
            mean, ci = metrics.mean_ci(col["exploration_steps"])
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
                "mean": mean,
                "ci95": ci,
                "greedy_mean": metrics.mean_ci(col["greedy_steps"])[0],
                "total_mean": metrics.mean_ci(col["total_steps"])[0],
                "converged": sum(bool(c) for c in col["converged"]),
                "improvement_percent": None,
                "improvement_ci95": None,
            }
            if base is not None and label != "none":
                bmean = metrics.mean_ci(base["exploration_steps"])[0]
                row["improvement_percent"] = metrics.improvement_percent(bmean, mean)
                row["improvement_ci95"] = metrics.improvement_ci(base["exploration_steps"], col["exploration_steps"])
            rows.append(row)
    return rows


def _task_name(row: dict) -> str:
    if row["task"] is not None:
        return f"task {row['task']}"
    return f"({row['start'][0]},{row['start'][1]})->({row['goal'][0]},{row['goal'][1]})"


def summary_markdown(rows: list[dict]) -> str:
    header = ["task", "source -> target", "wind", "eps", "lambda", "method", "trials",
              "exploration steps [95% CI]", "improvement % [95% CI]", "greedy", "converged"]
    body = [[
        _task_name(r), f"{r['source']} -> {r['target']}", f"{r['wind']:g}", f"{r['epsilon']:g}", f"{r['lam']:g}",
        r["method"], str(r["trials"]), f"{fmt_num(r['mean'])} {fmt_ci(r['ci95'])}",
        "" if r["method"] == "none" else f"{fmt_num(r['improvement_percent'])} {fmt_ci(r['improvement_ci95'])}",
        fmt_num(r["greedy_mean"]), f"{r['converged']}/{r['trials']}",
    ] for r in rows]
    return markdown_table(header, body)


def plot(rows: list[dict], path) -> None:
    from armtransfer.learning.figures import bar_chart

    groups: list[str] = []
    series: dict[str, dict[str, tuple]] = {}
    for r in rows:
        g = f"{_task_name(r)}\n{r['source']}->{r['target']}" + (f"\nwind {r['wind']:g}" if r["wind"] else "")
        if g not in groups:
            groups.append(g)
        series.setdefault(r["method"], {})[g] = (r["mean"], r["ci95"])
    data = {m: ([v.get(g, (None, None))[0] for g in groups], [v.get(g, (None, None))[1] for g in groups])
            for m, v in series.items()}
    bar_chart(groups, data, "exploration steps to the goal (95% CI)", "steps", path)

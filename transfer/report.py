"""Text tables of experiment summaries (Table II style), for terminals and report.md."""

from __future__ import annotations


def fmt_num(x: float | None, digits: int = 1) -> str:
    return "n/a" if x is None else f"{x:,.{digits}f}"


def fmt_ci(ci: list[float] | None, digits: int = 1) -> str:
    return "n/a" if ci is None else f"[{ci[0]:,.{digits}f}, {ci[1]:,.{digits}f}]"


def markdown_table(header: list[str], rows: list[list[str]]) -> str:
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    line = lambda cells: "| " + " | ".join(c.ljust(w) for c, w in zip(cells, widths)) + " |"  # noqa: E731
    sep = "|" + "|".join("-" * (w + 2) for w in widths) + "|"
    return "\n".join([line(header), sep, *(line(r) for r in rows)])


def method_table(results: dict) -> str:
    """One row per method: exploration steps (mean, 95% CI, over the trials that reached the
    goal), improvement, greedy steps, total steps, and how many trials reached and converged."""
    header = [
        "method",
        "exploration steps",
        "95% CI",
        "improvement %",
        "improvement 95% CI",
        "greedy steps",
        "steps to converge",
        "reached",
        "converged",
    ]
    rows = []
    for method, r in results.items():
        conv = r.get("converged", [])
        ex = r.get("exploration_steps", [])
        rows.append(
            [
                method,
                fmt_num(r["mean"]),
                fmt_ci(r["ci95"]),
                fmt_num(r.get("improvement_percent")),
                fmt_ci(r.get("improvement_ci95")),
                fmt_num(r.get("greedy_mean")),
                fmt_num(r.get("total_mean"), 0),
                f"{sum(x is not None for x in ex)}/{len(ex)}",
                f"{sum(bool(c) for c in conv)}/{len(conv)}",
            ]
        )
    return markdown_table(header, rows)

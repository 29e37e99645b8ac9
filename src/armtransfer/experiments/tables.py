"""Text tables of experiment summaries (Table II style) and their numbers, for terminals, a
result's repr and report.md. Nothing of the project is imported here: the results, the commands
and the reports all print with it."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable


def fmt_num(x: float | None, digits: int = 1) -> str:
    return "n/a" if x is None else f"{x:,.{digits}f}"


def fmt_ci(ci: list[float] | None, digits: int = 1) -> str:
    return "n/a" if ci is None else f"[{ci[0]:,.{digits}f}, {ci[1]:,.{digits}f}]"


def fmt_mean(entry: dict, digits: int = 1) -> str:
    """A summary entry's mean exploration steps, as a lower bound (``>= x``) when some trial
    never reached the goal and counts at the step cap."""
    text = fmt_num(entry.get("mean"), digits)
    return f"≥ {text}" if entry.get("mean_is_lower_bound") and entry.get("mean") is not None else text


def fmt_reached(entry: dict) -> str:
    """``reached k/n``: how many trials reached the goal at all."""
    ex = entry.get("exploration_steps", [])
    k = entry.get("reached", sum(x is not None for x in ex))
    return f"{k}/{len(ex)}"


def fmt_median(entry: dict, digits: int = 1, note: bool = True) -> str:
    """Median [order-statistic CI]; with ``note`` the CI's coverage is named when below 95%
    (fewer than 6 trials), and ``≥`` marks a median that censoring reached."""
    cov = entry.get("median_ci_coverage")
    remark = f" ({100 * cov:.0f}% CI)" if note and cov is not None and cov < 0.95 else ""
    return (("≥ " if entry.get("median_is_lower_bound") else "")
            + f"{fmt_num(entry.get('median'), digits)} {fmt_ci(entry.get('median_ci95'), digits)}{remark}")


def _coverage(entry: dict) -> str | None:
    cov = entry.get("median_ci_coverage")
    return None if cov is None else ("95%" if cov >= 0.95 else f"{100 * cov:.0f}%")


def median_column(entries: Iterable[dict]) -> tuple[str, Callable[[dict], str]]:
    """(header, cell formatter) of a median column: the header names the coverage its CIs hold
    (``median [75% CI]`` for 3 trials, ``median [95% CI]`` from 6 on); only where the rows'
    coverages differ does each cell name its own."""
    coverages = {_coverage(e) for e in entries} - {None}
    if len(coverages) <= 1:
        label = coverages.pop() if coverages else "95%"
        return f"median [{label} CI]", lambda e: fmt_median(e, note=False)
    return "median [CI, coverage named when below 95%]", fmt_median


CAP_MARK = "‡"
CAP_NOTE = (f"{CAP_MARK}: unreached trials counted at the step cap make up more than half of a mean; that "
            "improvement says more about the cap than about the method (read the medians).")


def fmt_improvement(entry: dict) -> str:
    """An improvement in percent, marked when a cap-dominated mean entered it."""
    text = fmt_num(entry.get("improvement_percent"))
    return text + CAP_MARK if entry.get("improvement_cap_dominated") else text


def markdown_table(header: list[str], rows: list[list[str]]) -> str:
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    line = lambda cells: "| " + " | ".join(c.ljust(w) for c, w in zip(cells, widths)) + " |"  # noqa: E731
    sep = "|" + "|".join("-" * (w + 2) for w in widths) + "|"
    return "\n".join([line(header), sep, *(line(r) for r in rows)])


def method_table(results: dict) -> str:
    """One row per method: exploration steps over ALL trials (an unreached trial counts at
    the step cap, and the mean is then marked as a lower bound ``≥``), its 95% CI, the
    median with its CI (the header names its coverage), the mean improvement (with its
    design), the mean greedy path and steps to converge, and how many trials reached the
    goal and converged."""
    median_header, median_cell = median_column(results.values())
    header = [
        "method",
        "reached goal",
        "mean exploration steps",
        "mean's 95% CI",
        median_header,
        "mean improvement %",
        "improvement 95% CI",
        "mean greedy steps",
        "mean steps to converge",
        "converged",
    ]
    rows = []
    for method, r in results.items():
        conv = r.get("converged", [])
        rows.append(
            [
                method,
                fmt_reached(r),
                fmt_mean(r),
                fmt_ci(r["ci95"]),
                median_cell(r),
                fmt_improvement(r),
                fmt_ci(r.get("improvement_ci95")),
                fmt_num(r.get("greedy_mean")),
                fmt_num(r.get("total_mean"), 0),
                f"{sum(bool(c) for c in conv)}/{len(conv)}",
            ]
        )
    designs = {r.get("improvement_design") for r in results.values()} - {None}
    table = markdown_table(header, rows)
    if any(r.get("mean_is_lower_bound") for r in results.values()):
        table += ("\n\n≥: some trials never reached the goal; they count at the step cap, so the mean "
                  "is a lower bound.")
    if any(r.get("improvement_cap_dominated") for r in results.values()):
        table += "\n\n" + CAP_NOTE
    if designs:
        table += "\n\nImprovement CIs: " + "; ".join(sorted(designs)) + "."
    return table


def _baseline_of(entry: dict) -> str | None:
    """The baseline that shares a row's learner (the no-transfer one first), or None for a
    baseline's own row."""
    return next(iter(entry.get("improvement_against") or {}), None)


def transfer_order(out: dict) -> list[tuple[str, dict]]:
    """A transfer's rows in reading order: the baselines first, then each method followed by
    its control runs (``method [kind]``). ``out`` is ``TransferResult.to_json()``."""
    results = out["results"]
    controls = out.get("controls", {})
    rows = [(m, e) for m, e in results.items() if _baseline_of(e) is None]
    for m, e in results.items():
        if _baseline_of(e) is not None:
            rows.append((m, e))
            rows.extend((f"{m} [{kind}]", by[m]) for kind, by in controls.items() if m in by)
    return rows


def _good_median(e: dict) -> str:
    """The median steps to a good path (a trial never good counts as beyond its steps run) and
    how many trials ended on one."""
    good = e.get("good_path_steps") or []
    if not good or all(v is None and r is None for v, r in zip(good, e.get("steps_run") or [None] * len(good))):
        return "n/a"
    runs = e.get("steps_run") or [None] * len(good)
    vals = sorted((float("inf") if v is None else float(v)) for v in good)
    mid = vals[(len(vals) - 1) // 2] if len(vals) % 2 else (vals[len(vals) // 2 - 1] + vals[len(vals) // 2]) / 2
    ended = sum(v is not None for v in good)
    shown = f"> {max((r for r in runs if r is not None), default=0):,}" if mid == float("inf") else f"{mid:,.0f}"
    return f"{shown} ({ended}/{len(good)} good)"


def _good_factor(e: dict, base: dict | None, cap: int) -> str:
    """The geometric mean over paired trials of baseline / method steps to a good path (a trial not
    good at its end counts at the step cap, marked †: a bound), and the worst trial."""
    if base is None:
        return "n/a"
    mine, theirs = e.get("good_path_steps") or [], base.get("good_path_steps") or []
    if not mine or len(mine) != len(theirs) or all(v is None for v in (*mine, *theirs)):
        return "n/a"
    logs = [math.log(max(cap if b is None else b, 1) / max(cap if m is None else m, 1)) for m, b in zip(mine, theirs)]
    mark = "†" if any(v is None for v in (*mine, *theirs)) else ""
    return f"{math.exp(sum(logs) / len(logs)):.2f}x{mark} (worst {math.exp(min(logs)):.2f}x)"


def _settled(e: dict) -> str:
    ratios = [r for r in e.get("settled_ratio") or [] if r is not None]
    if not ratios:
        return "n/a"
    ratios.sort()
    mid = ratios[(len(ratios) - 1) // 2] if len(ratios) % 2 else (ratios[len(ratios) // 2 - 1] + ratios[len(ratios) // 2]) / 2
    return f"{mid:.2f} ({ratios[-1]:.2f})"


GOOD_NOTE = ("Good path: steps until the greedy path is within ceil(quality x shortest) steps and stays so (a trial "
             "ends only on a settled good path, so one that settles on a longer path runs on to a cap); the factor "
             "is the baseline's steps over the method's, a geometric mean over paired trials (†: some trial never "
             "reached a good path and counts at the step cap, so the factor is a bound, not an estimate). Settled "
             "ratio: the first settled greedy path over the shortest. Settled clock: steps until the greedy path "
             "first stopped changing, however long.")


def transfer_table(out: dict) -> str:
    """A transfer as one table, the good-path clock first: each method beside the baseline that
    shares its learner, and under it its control runs. Columns: steps to a good path (median, and
    the factor against the row's baseline) with the settled quality beside it, then steps to
    convergence (the settled clock), then the first exposure (exploration steps, mean and median),
    then the improvement of the first exposure over the row's baseline; ``out`` is
    ``TransferResult.to_json()``."""
    rows_in = transfer_order(out)
    by_label = dict(rows_in)
    cap = int(out.get("config", {}).get("max_total_steps") or 0)
    median_header, median_cell = median_column(e for _, e in rows_in)
    header = ["method", "baseline", "good path: median steps", "good path vs baseline", "settled ratio: median (worst)",
              "settled clock: mean steps", "converged", "reached goal",
              "mean exploration steps [95% CI]", median_header, "improvement over baseline % [95% CI]",
              "mean greedy steps"]
    rows, designs, capped = [], set(), False
    for label, e in rows_in:
        base = _baseline_of(e)
        conv = e.get("converged", [])
        against = (e.get("improvement_against") or {}).get(base) if base else None
        if against is None:
            improvement = "n/a"
        else:
            improvement = fmt_num(against.get("percent")) + (CAP_MARK if against.get("cap_dominated") else "")
            improvement += " " + fmt_ci(against.get("ci95"))
            designs.add(against.get("design"))
            capped |= bool(against.get("cap_dominated"))
        rows.append([label, base or "(baseline)", _good_median(e),
                     _good_factor(e, by_label.get(base) if base else None, cap), _settled(e),
                     fmt_num(e.get("total_mean"), 0),
                     f"{sum(bool(c) for c in conv)}/{len(conv)}", fmt_reached(e),
                     f"{fmt_mean(e)} {fmt_ci(e.get('ci95'))}", median_cell(e), improvement,
                     fmt_num(e.get("greedy_mean"))])
    table = markdown_table(header, rows) + "\n\n" + GOOD_NOTE
    if any(e.get("mean_is_lower_bound") for _, e in rows_in):
        table += ("\n\n≥: some trials never reached the goal; they count at the step cap, so the mean "
                  "is a lower bound.")
    if capped:
        table += "\n\n" + CAP_NOTE
    designs.discard(None)
    if designs:
        table += "\n\nImprovement CIs: " + "; ".join(sorted(designs)) + "."
    return table


CONTROLS_NOTE = ("[shuffled] and [random] are controls, the method given the trajectory's cells in a random order "
                 "or a random walk of the same length: a control that does as well as its method, within the "
                 "intervals, means this many trials cannot credit the gain to the trajectory's route.")


def transfer_heading(out: dict) -> str:
    """The line above a transfer's table: task, robots, distance, trials, seed (and wind)."""
    t = out["task"]
    world = f"world {out['world']}, " if out.get("world") else ""
    return (f"{world}{t['name']}: {tuple(t['start'])} -> {tuple(t['goal'])}, {out['source']} -> {out['target']}, "
            f"target's optimal distance {out['distance']}, {out['trials']} trials, seed {out['seed']}"
            + (f", wind {out['wind']}" if out["wind"] else "")
            + (f", learner {out['learner']} (each method beside the none it runs; no controls)" if out.get("learner") else ""))

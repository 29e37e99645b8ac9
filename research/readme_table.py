"""The README's benchmark tables, made from a benchmark's results file and nothing else.

    python research/readme_table.py docs/benchmark-standard/results.json.gz

prints markdown tables, one row per section of the suite and one column per method against a
baseline that shares its learner: the good-path clock first (steps until the greedy path is
within the quality threshold of the shortest and stays so), with the settled quality of the
method's and the baseline's trials beside it (median and worst first settled path over the
shortest); then the settled clock (steps until the greedy path first settled, however long); the
first exposure is in the report. A cell is the factor (baseline / method, above 1 the method is faster), its
95% hierarchical bootstrap-t interval and the worst case x source seed pair; a verdict that
survives Holm's correction is marked "faster" or "slower"; "n.s." is not told apart at this size,
"n.s. (Holm)" an interval that excludes 1 before Holm's correction and not after, "too few" no
interval (fewer units than the minimum); "k bounds" counts the pairs where one trial hit the cap.
`lazy` vs `plan` is the control: told nothing and exploring less, it must not be faster.
tests/test_benchmark_file.py checks that the README shows exactly these tables for the results
file kept in docs/.
"""

from __future__ import annotations

import sys
from pathlib import Path

from armtransfer.commands.benchmark_file import read_results
from armtransfer.errors import ArmTransferError
from armtransfer.experiments.reports.benchmark_report import judgement

COLUMNS = (("pseudo", "none"), ("dense", "none"), ("dense", "goal-dense"), ("guided", "plan"), ("corridor", "plan"),
           ("guided", "goal-only"), ("corridor", "goal-only"), ("pseudo-plan", "plan"), ("lazy", "plan"))
"""(method, baseline) pairs shown, each a method against a baseline sharing its learner; the last
is the control."""

SECTIONS = {"paper": "paper (Table I)", "random": "random tasks", "embodiment": "joint-space arms",
            "wind": "wind 0.01-0.1"}


def _x(f: float) -> str:
    return f"{f:.3g}×" if f < 100 else f"{f:,.0f}×"


def mark(ab: dict) -> str:
    verdict = judgement(ab)
    if verdict.startswith(("faster", "slower")):
        return verdict.split(" ")[0]
    if verdict.startswith("too few"):
        return "too few"
    return "n.s. (Holm)" if "after Holm's correction" in verdict else "n.s."


def cell(ab: dict | None) -> str:
    if ab is None or ab.get("factor") is None:
        return "n/a"
    ci = ab["ci95"]
    bounds = f", {ab['bounds']} bounds" if ab.get("bounds") else ""
    interval = f" [{_x(ci[0])}, {_x(ci[1])}]" if ci else ""
    return f"{_x(ab['factor'])}{interval}, {_x(ab['worst'])}, {mark(ab)}{bounds}"


def _q(q: dict | None) -> str:
    if not q or q.get("median") is None:
        return "-"
    return f"{q['median']:.2f}/{q['worst']:.2f}"


def good_cell(block: dict | None) -> str:
    """The good-path factor with the settled quality (median/worst ratio) of method and baseline."""
    if block is None:
        return "n/a"
    good = block.get("good_path")
    if good is None or good.get("factor") is None:
        return "not measured"
    settled = block.get("settled", {})
    return f"{cell(good)}; settled {_q(settled.get('method'))} vs {_q(settled.get('baseline'))}"


def tables(summary: dict, settled: bool = True) -> str:
    header = "| suite | " + " | ".join(f"`{m}` vs `{b}`" for m, b in COLUMNS) + " |"
    rule = "|---|" + "---|" * len(COLUMNS)
    out = ["**Good path: steps until the greedy path is within 5% of the shortest and stays there; "
           "settled quality (first settled path / shortest, median/worst) of method vs baseline**", "", header, rule]
    for section, pooled in summary.items():
        row = [good_cell(pooled.get(m, {}).get(b)) for m, b in COLUMNS]
        out.append(f"| {SECTIONS.get(section, section)} | " + " | ".join(row) + " |")
    out.append("")
    for metric, title in (("convergence", "Settled clock: steps until the greedy path first settled, however long"),)[:int(settled)]:
        out += [f"**{title}**", "", header, rule]
        for section, pooled in summary.items():
            row = [cell(pooled.get(m, {}).get(b, {}).get(metric)) for m, b in COLUMNS]
            out.append(f"| {SECTIONS.get(section, section)} | " + " | ".join(row) + " |")
        out.append("")
    return "\n".join(out).rstrip("\n") + "\n"


def compact_cell(block: dict | None) -> str:
    """A compact good-path cell: factor, interval and verdict; the worst pair; the settled quality
    (median/worst first settled path over the shortest) of method vs baseline."""
    if block is None:
        return "n/a"
    good = block.get("good_path")
    if good is None or good.get("factor") is None:
        return "not measured"
    ci = good["ci95"]
    interval = f" [{_x(ci[0])[:-1]}, {_x(ci[1])}]" if ci else ""
    bounds = f", {good['bounds']} pairs capped" if good.get("bounds") else ""
    settled = block.get("settled", {})
    return (f"{_x(good['factor'])}{interval} {mark(good)}; worst {_x(good['worst'])}{bounds}; "
            f"{_q(settled.get('method'))} vs {_q(settled.get('baseline'))}")


def compact(summary: dict) -> str:
    """The README's one headline table: a row per method against a baseline sharing its learner,
    a column per section of the suite, each cell the good-path clock (:func:`compact_cell`)."""
    sections = list(summary)
    out = ["| method vs baseline | " + " | ".join(SECTIONS.get(s, s) for s in sections) + " |",
           "|---|" + "---|" * len(sections)]
    for m, b in COLUMNS:
        out.append(f"| `{m}` vs `{b}` | " + " | ".join(compact_cell(summary[s].get(m, {}).get(b)) for s in sections)
                   + " |")
    return "\n".join(out) + "\n"


LEARNER_COLUMNS = (("pseudo", "good_path"), ("dense", "good_path"), ("pseudo", "convergence"), ("dense", "convergence"),
                   ("pseudo", "first_exposure"), ("dense", "first_exposure"))
"""The learner table's columns: each transfer method against its learner's own ``none``."""


def _learner_cell(block: dict | None, metric: str) -> str:
    if metric == "good_path":
        return good_cell(block)
    return cell(None if block is None else block.get(metric))


def learner_table(summary: dict) -> str:
    """One row per learner of a suite that names several (``small``): each transfer method
    against the ``none`` of the same learner, pooled over the suite's sections' cases."""
    names = {"good_path": "good path", "convergence": "settled clock", "first_exposure": "first exposure"}
    header = ("| learner | " + " | ".join(f"`{m}` vs `none`, {names[k]}" for m, k in LEARNER_COLUMNS) + " |")
    out = [header, "|---|" + "---|" * len(LEARNER_COLUMNS)]
    for section, pooled in summary.items():
        learners = sorted({n.split("@")[1] for n in pooled if "@" in n})
        for learner in ["sarsa", *learners]:
            tag = "" if learner == "sarsa" else f"@{learner}"
            row = [_learner_cell(pooled.get(f"{m}{tag}", {}).get(f"none{tag}"), k) for m, k in LEARNER_COLUMNS]
            name = learner if len(summary) == 1 else f"{section}: {learner}"
            out.append(f"| {name} | " + " | ".join(row) + " |")
    return "\n".join(out) + "\n"


def pooled(path: Path) -> dict:
    data, _ = read_results(path)
    return {name: sec["pooled"] for name, sec in data["summary"].items()}


def main(argv: list[str] | None = None) -> int:
    from armtransfer import script

    p = script.parser(__doc__)
    p.add_argument("results", type=Path, help="a benchmark's results.json or results.json.gz")
    p.add_argument("--good-only", action="store_true", help="the good-path table alone")
    p.add_argument("--compact", action="store_true", help="the README's headline table: a row per comparison, "
                   "a column per section, the good-path clock with the settled quality")
    p.add_argument("--learners", action="store_true",
                   help="one row per learner (a suite with several, such as small) instead of one per section")
    args = p.parse_args(argv)
    try:
        summary = pooled(args.results)
        if args.learners:
            text = learner_table(summary)
        elif args.compact:
            text = compact(summary)
        else:
            text = tables(summary, settled=not args.good_only)
    except ArmTransferError as err:
        print(f"readme_table.py: error: {err}", file=sys.stderr)
        return 2
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    from armtransfer import script

    script.exit_with(main)

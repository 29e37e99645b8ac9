"""The benchmark's report: report.md and its figures, every sentence built from the run's numbers."""

from __future__ import annotations

from pathlib import Path

from armtransfer.experiments.reports import figures

from armtransfer.experiments import suites
from armtransfer.experiments.reports.report import fmt_num, markdown_table
from armtransfer.learning import methods


def survival_name(section: str) -> str:
    return f"survival_{section}.png"


def curves_name(section: str) -> str:
    return f"learning_curves_{section}.png"


def _steps(x: float | None, beyond: bool = False, cap: float | None = None) -> str:
    if x is None:
        return f"> {cap:,.0f}" if beyond and cap is not None else "n/a"
    return f"{x:,.0f}"


def _km(block: dict, cap: float) -> str:
    lo, hi = block["km_median_ci95"]
    med = _steps(block["km_median"], True, cap)
    return f"{med} [{_steps(lo, True, cap)}, {_steps(hi, True, cap)}]"


def _factor(f: float | None) -> str:
    return "n/a" if f is None else f"{f:.2f}x"


def _factor_ci(ab: dict | None) -> str:
    if ab is None or ab["factor"] is None:
        return "n/a"
    ci = ab["ci95"]
    return f"{_factor(ab['factor'])} [{_factor(ci[0]) if ci else 'n/a'}, {_factor(ci[1]) if ci else 'n/a'}]"


def _pct(x: float | None) -> str:
    return "n/a" if x is None else f"{100 * x:.0f}%"


def judgement(ab: dict) -> str:
    """What a paired factor's interval allows one to say, from its numbers alone."""
    ci = ab.get("ci95")
    if ab.get("factor") is None:
        return "no comparison"
    if ab["n"] < suites.MIN_SEEDS_FOR_CLAIM or ci is None:
        return f"too few pairs for a claim ({ab['n']} < {suites.MIN_SEEDS_FOR_CLAIM})"
    if ci[0] > 1:
        return "faster than its baseline"
    if ci[1] < 1:
        return "slower than its baseline"
    return (f"cannot be told apart from its baseline at this size (the interval spans 1; only factors "
            f"outside {ci[0]:.2f}x-{ci[1]:.2f}x would have shown)")


def sentence(name: str, ab: dict, where: str) -> str:
    """One claim about ``name`` against one of its baselines, from the pooled factor ``ab``."""
    from armtransfer.experiments.benchmark import baselines_of, registered_baseline

    if not registered_baseline(name):
        whose = "the default baseline: this build's registry names none for it"
    elif baselines_of(name)[:1] == (ab["baseline"],):
        whose = "its baseline: the same learner, told nothing"
    else:
        whose = "a baseline sharing its learner and told less: what the rest of the transfer adds"
    text = (f"{where}: `{name}` reached the goal first {_factor_ci(ab)} as fast as `{ab['baseline']}` ({whose}; "
            f"geometric mean over {ab['n']} case x source-seed pairs, 95% bootstrap interval; worst pair "
            f"{_factor(ab['worst'])}): {judgement(ab)}.")
    conv = ab.get("convergence")
    if conv is not None:
        text += (f" Its greedy path settled {_factor_ci(conv)} as fast (worst pair {_factor(conv['worst'])}): "
                 f"{judgement(conv)}.")
    for what, block in (("first exposure", ab), ("convergence", conv or {})):
        if block.get("seeds_with_censored_median"):
            text += (f" In {block['seeds_with_censored_median']} pairs a median {what} was at the step cap, so "
                     "those factors are bounds, not values.")
    return text


def _against(e: dict, key: str | None = None) -> str:
    parts = [f"{b}: {_factor_ci(ab if key is None else ab[key])} ({_factor((ab if key is None else ab[key])['worst'])})"
             for b, ab in e["against"].items()]
    return "; ".join(parts) or "-"


def _transfer_ratio(e: dict) -> str:
    parts = []
    for b, ab in e["against"].items():
        ci = ab["transfer_ratio_ci95"]
        if ab["transfer_ratio"] is not None:
            parts.append(f"{b}: {_pct(ab['transfer_ratio'])} [{_pct(ci[0]) if ci else 'n/a'}, "
                         f"{_pct(ci[1]) if ci else 'n/a'}]")
    return "; ".join(parts) or "-"


def case_table(case: dict, cap: float) -> str:
    header = ["method", "baselines", "first exposure, KM median [95%]", "median over seeds [95%]", "worst seed",
              "failed", "success in budget", "convergence, KM median [95%]", "area (100 ep.)",
              "first exposure vs each baseline [95%] (worst seed)", "convergence vs each baseline", "transfer ratio [95%]"]
    rows = []
    for name, e in case["methods"].items():
        fe = e["first_exposure"]
        worst = ("≥ " if fe["worst_seed_is_lower_bound"] else "") + _steps(fe["worst_seed"])
        seeds_ci = fe["median_over_seeds_ci95"]
        rows.append([
            name + (" (error)" if e["errors"] else ""), ", ".join(e["baselines"]) or "-", _km(fe, cap),
            f"{_steps(fe['median_over_seeds'])} [{_steps(seeds_ci[0]) if seeds_ci else 'n/a'}, "
            f"{_steps(seeds_ci[1]) if seeds_ci else 'n/a'}]",
            worst, _pct(e["failure_rate"]), _pct(e["success_rate"]), _km(e["convergence"], cap),
            fmt_num(e["area"]["mean"], 0), _against(e), _against(e, "convergence"), _transfer_ratio(e),
        ])
    return markdown_table(header, rows)


def write_figures(summary: dict, suite: suites.Suite, out: Path) -> None:
    for section in suite.sections:
        sec = summary[section.name]
        figures.survival_grid(
            [(c["label"], {m: (e["survival"]["times"], e["survival"]["survival"]) for m, e in c["methods"].items()})
             for c in sec["cases"]], section.max_total_steps,
            f"{section.name}: Kaplan-Meier curves of the first exposure", out / survival_name(section.name))
        figures.curve_grid([(c["label"], {m: e["curve_mean"] for m, e in c["methods"].items()}) for c in sec["cases"]],
                           f"{section.name}: learning curves", out / curves_name(section.name))


def report_markdown(suite: suites.Suite, seed: int, summary: dict, ran: list[str], missing: list[str]) -> str:
    from armtransfer.experiments.benchmark import baselines_of, registered_baseline

    kind = ("held out: no parameter of any method was chosen on it" if suite.held_out
            else "not held out: parameters may be chosen on it")
    out = [f"# Benchmark `{suite.name}` (version {suite.version})", "",
           f"Made by `armtransfer benchmark --suite {suite.name} --seed {seed}`. {suite.description}; {kind}.", "",
           "## Methods and their baselines", "",
           "Every method's gain is measured against the baseline that shares its learner and differs only "
           "in what is transferred; each baseline is run beside it on the same random streams.", ""]
    out.append(markdown_table(["method", "baselines (the first: told nothing)", "what it is"],
                              [[m, (", ".join(baselines_of(m)) or "-") + ("" if m == "none" or registered_baseline(m)
                                                                          else " (default: the registry names none)"),
                                methods.get(m).description] for m in ran]))
    if missing:
        out += ["", f"Not in this build's method registry, so not run: {', '.join(missing)}."]
    out += ["", "## Claims", ""]
    for section in suite.sections:
        for name, against in summary[section.name]["pooled"].items():
            for ab in against.values():
                out.append("- " + sentence(name, ab, section.name))
    for section in suite.sections:
        sec = summary[section.name]
        out += ["", f"## Section `{section.name}`", "",
                f"{section.description}. {len(section.cases)} cases; for each, {section.source_seeds} source "
                f"seeds (robot 1 learns the task again for each and hands over its converged greedy path) x "
                f"{section.trials} trials of every method; a trial stops at {section.max_total_steps:,} steps, "
                f"and a first exposure not reached by then is censored there. Success: the goal first reached "
                f"within {suites.BUDGET_FACTOR}x the target's shortest path.", "",
                f"![survival curves]({survival_name(section.name)})", "",
                f"![learning curves]({curves_name(section.name)})"]
        for case in sec["cases"]:
            opt = case["optimal_per_seed"]
            dist = f"{opt[0]}" if len(set(opt)) == 1 else f"{min(opt)}-{max(opt)} (per seed)"
            out += ["", f"### {case['label']}", "", f"Target's shortest path: {dist} steps.", "",
                    case_table(case, section.max_total_steps)]
            errors = {m: e["errors"] for m, e in case["methods"].items() if e["errors"]}
            for m, errs in errors.items():
                out.append(f"\n`{m}` could not run on some source seeds (counted as failed): {'; '.join(errs)}")
    out += ["", "## How to read this report", "",
            "- First exposure: steps until robot 2 first reaches the goal. KM median: the Kaplan-Meier median "
            "over every trial, unreached trials censored at the cap ('> cap' where the curve never falls to "
            "one half). Median over seeds: the median of each source seed's median; worst seed: the largest "
            "of these ('≥': censoring reached it).",
            "- Failed: trials that never reached the goal within the cap. Success in budget: trials that "
            "reached it within the budget.",
            "- Convergence: steps until the greedy path stopped changing (censored at the cap when it never did).",
            "- Area: the area under the learning curve, steps of the first 100 episodes (a converged trial "
            "continues at its greedy length).",
            "- vs each baseline: baseline / method of the seeds' median first exposures (or convergence steps), "
            "paired by source seed, geometric mean with a percentile bootstrap interval over seeds (it stays inside "
            "the factors seen); above 1 the method is faster. Transfer ratio (Taylor and Stone): the share of the baseline's area "
            "that the method saves, mean over seeds.",
            ""]
    return "\n".join(out)

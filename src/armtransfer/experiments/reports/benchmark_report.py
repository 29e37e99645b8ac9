"""The benchmark's report: report.md and its figures, every sentence built from the run's numbers."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from armtransfer.experiments import harness_terms as lt
from armtransfer.experiments import suites
from armtransfer.experiments.comparisons import baselines_of, registered_baseline
from armtransfer.experiments.reports import figures
from armtransfer.experiments.tables import markdown_table
from armtransfer.experiments.stats.hierarchical import MIN_UNITS
from armtransfer.experiments.stats.learning_metrics import HORIZON
from armtransfer.experiments.stats.multiplicity import ALPHA
from armtransfer.learning import methods
from armtransfer.learning.learner_names import parse_label
from armtransfer.learning.learners import LEARNERS


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
    """What a paired factor allows one to say, from its numbers alone: a verdict only from
    enough source seeds and a Holm-adjusted p below 5%; otherwise what could have been seen."""
    ci = ab.get("ci95")
    if ab.get("factor") is None:
        return "no comparison"
    seeds = ab.get("seeds", ab.get("n", 0))
    if seeds < suites.MIN_SEEDS_FOR_CLAIM:
        return f"too few pairs for a claim ({seeds} < {suites.MIN_SEEDS_FOR_CLAIM})"
    if ci is None:
        return (f"too few units for an interval ({ab.get('units', 0)} < {MIN_UNITS} "
                f"{'cases' if ab.get('cases', 0) > 1 else 'source seeds'})")
    p = ab.get("p_holm")
    holm = f"Holm-adjusted p = {p:.3g} over {ab.get('verdicts', 1)} verdicts" if p is not None else "no p-value"
    if p is not None and p < ALPHA:
        return f"{'faster' if ab['factor'] > 1 else 'slower'} than its baseline ({holm})"
    det = ab.get("detectable")
    seen = (f"; at 80% power only factors below {det[0]:.2f}x or above {det[1]:.2f}x would have shown"
            if det else "")
    if p is not None and (ci[0] > 1 or ci[1] < 1):  # the unadjusted interval excludes 1, the verdict does not hold
        return (f"cannot be told apart from its baseline after Holm's correction: its 95% interval, not adjusted "
                f"for the report's {ab.get('verdicts', 1)} verdicts, excludes 1, but {holm}{seen}")
    return f"cannot be told apart from its baseline at this size ({holm}{seen})"


def _pairs_note(block: dict) -> str:
    parts = []
    if block.get("ties"):
        parts.append(f"{block['ties']} trial pairs capped in both are ties, left out")
    if block.get("bounds"):
        parts.append(f"{block['bounds']} capped in one give bounds")
    return f" ({'; '.join(parts)})" if parts else ""


def _ratio(x: float | None) -> str:
    return "n/a" if x is None else f"{x:.2f}"


def quality_text(q: dict | None) -> str:
    """The settled quality of a set of trials: the median and worst first settled path over the
    shortest, and how many trials ended on a good path."""
    if not q or q.get("median") is None:
        return "no settled path"
    return (f"settled at {_ratio(q['median'])}x the shortest (median; worst {_ratio(q['worst'])}x), "
            f"{q['good_at_end']} of {q['trials']} ending on a good path")


def good_path_text(ab: dict, base: str) -> str:
    """The good-path clock of one pooled comparison with the settled quality of both sides."""
    good = ab.get("good_path")
    if good is None or good.get("factor") is None:
        return ("Good path: not measured (records written before the good-path clock, or a continuous target, "
                "whose shortest path is not known).")
    settled = ab.get("settled", {})
    return (f"Good path: {_factor_ci(good)} as fast (worst seed {_factor(good['worst'])}){_pairs_note(good)}: "
            f"{judgement(good)}; it {quality_text(settled.get('method'))}, `{base}` "
            f"{quality_text(settled.get('baseline'))}.")


def _wins_then_loses(ab: dict) -> bool:
    """The first exposure is judged faster and the whole cost is not (slower, or no verdict)."""
    fe, conv = ab.get("first_exposure", {}), ab.get("convergence", {})
    if not judgement(fe).startswith("faster"):
        return False
    return not judgement(conv).startswith("faster") and not judgement(conv).startswith("too few")


def sentence(name: str, ab: dict, where: str) -> str:
    """One claim about ``name`` against one of its baselines, from the pooled comparison ``ab``
    (one block per metric): the whole cost first, then the first exposure, then the transfer
    ratio, and whether a first-episode win is lost back."""

    base = ab["baseline"]
    if not registered_baseline(name):
        whose = "the default baseline: this build's registry names none for it"
    elif baselines_of(name)[:1] == (base,):
        whose = "its baseline: the same learner, told nothing"
    else:
        whose = "a baseline sharing its learner and told less: what the rest of the transfer adds"
    conv, fe, cost = ab["convergence"], ab["first_exposure"], ab["cost"]
    cases = f"{conv['cases']} case{'s' if conv['cases'] != 1 else ''}"
    text = (f"{where}: `{name}` against `{base}` ({whose}; {cases}, {conv['seeds']} source seeds, "
            f"geometric means with hierarchical bootstrap-t 95% intervals). "
            f"{good_path_text(ab, base)} "
            f"Settled clock (until its greedy path first settled, however long): {_factor_ci(conv)} as fast "
            f"(worst seed {_factor(conv['worst'])}){_pairs_note(conv)}: {judgement(conv)}. "
            f"First exposure: {_factor_ci(fe)} as fast (worst seed {_factor(fe['worst'])}){_pairs_note(fe)}: "
            f"{judgement(fe)}.")
    tr, ci = cost.get("transfer_ratio"), cost.get("transfer_ratio_ci95")
    if tr is not None:
        text += (f" Transfer ratio over the first {HORIZON} episodes: {_pct(tr)} "
                 f"[{_pct(ci[0]) if ci else 'n/a'}, {_pct(ci[1]) if ci else 'n/a'}] of `{base}`'s steps saved"
                 f"{_pairs_note(cost)}: {judgement(cost)}.")
    if _wins_then_loses(ab):
        verdict = "slower" if judgement(conv).startswith("slower") else "not faster"
        text += (f" It wins the first episode ({_factor(fe['factor'])}) and loses it back: by the settled clock it is "
                 f"{_factor_ci(conv)} as fast as `{base}` ({verdict})"
                 + (f", and it saves {_pct(tr)} of `{base}`'s steps over the first {HORIZON} episodes"
                    if tr is not None else "") + ".")
    return text


def control_text(where: str, pooled: dict) -> str | None:
    """What the control ``lazy`` says of the clocks in one section: told nothing and exploring
    less, it must not come out faster than ``plan`` on the headline (the good-path clock); the
    settled clock beside it shows what exploring less buys there."""
    ab = pooled.get("lazy", {}).get("plan")
    if ab is None:
        return None
    good, conv = ab.get("good_path") or {}, ab["convergence"]
    if good.get("factor") is None:
        return None
    bought = judgement(good).startswith("faster")
    return (f"{where}, control: `lazy` (`plan` with untried moves valued lower, told nothing) against `plan`: "
            f"good path {_factor_ci(good)} (worst seed {_factor(good['worst'])}): {judgement(good)}; settled clock "
            f"{_factor_ci(conv)}. " + ("**The good-path clock was bought by exploring less here: its claims do not "
                                       "hold.**" if bought else "Exploring less does not buy the headline here."))


def stratum_text(where: str, stratum: dict) -> str:
    """The comparisons over the (case, source seed) pairs on which robot 1 handed a trajectory
    over: a description beside the claims, with intervals and no verdict."""
    parts = [f"`{name}` against `{base}`: good path {_factor_ci(ab.get('good_path'))}, settled clock "
             f"{_factor_ci(ab['convergence'])} (worst seed "
             f"{_factor(ab['convergence']['worst'])}), first exposure {_factor_ci(ab['first_exposure'])} (worst seed "
             f"{_factor(ab['first_exposure']['worst'])})"
             for name, against in stratum["pooled"].items() for base, ab in against.items()]
    there = ("every method that needs a trajectory learned there as its baseline told nothing, the same learner "
             "on the same seeds, and the claims above count those pairs" if stratum.get("told_nothing") else
             "the claims above count every method that needs a trajectory as failed there")
    return (f"{where}, where robot 1 handed a trajectory over ({stratum['pairs']} of {stratum['of']} case x source "
            f"seed pairs; on the others it did not converge, and {there}). A description of that stratum, with no "
            "verdict: " + "; ".join(parts) + ".")


def _against(e: dict, key: str) -> str:
    parts = [f"{b}: {_factor_ci(ab[key])} ({_factor(ab[key]['worst'])})" for b, ab in e["against"].items()
             if key in ab]
    return "; ".join(parts) or "-"


def _transfer_ratio(e: dict) -> str:
    parts = []
    for b, ab in e["against"].items():
        c = ab["cost"]
        ci = c["transfer_ratio_ci95"]
        if c["transfer_ratio"] is not None:
            parts.append(f"{b}: {_pct(c['transfer_ratio'])} [{_pct(ci[0]) if ci else 'n/a'}, "
                         f"{_pct(ci[1]) if ci else 'n/a'}]")
    return "; ".join(parts) or "-"


def _quality_cell(e: dict) -> str:
    q = e.get("settled_quality") or {}
    if q.get("median") is None:
        return "-"
    return f"{_ratio(q['median'])} ({_ratio(q['worst'])}); {q['good_at_end']}/{q['trials']}"


def case_table(case: dict, cap: float) -> str:
    header = ["method", "baselines", "good path, KM median [95%]", "settled ratio, median (worst); good at end",
              "settled clock, KM median [95%]", "first exposure, KM median [95%]",
              "failed", "success in budget", "seed share", "good path vs each baseline [95%] (worst seed)",
              "settled clock vs each baseline", "first exposure vs each baseline", "transfer ratio [95%]"]
    rows = []
    for name, e in case["methods"].items():
        share = e.get("seed_share")
        good = e.get("good_path")
        rows.append([
            name + (" (error)" if e["errors"] else ""), ", ".join(e["baselines"]) or "-",
            "n/a" if good is None else _km(good, cap), _quality_cell(e), _km(e["convergence"], cap),
            _km(e["first_exposure"], cap), _pct(e["failure_rate"]), _pct(e["success_rate"]),
            "n/a" if share is None else f"{share:.2f}",
            _against(e, "good_path"), _against(e, "convergence"), _against(e, "first_exposure"), _transfer_ratio(e),
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


def record_warnings(records: list[dict]) -> list[str]:
    """Every distinct warning of the records (a potential of one's own squashed, constant or not
    0 at the goal: ``potentials.notes``), in order."""
    return list(dict.fromkeys(w for r in records for w in r.get("warnings") or ()))


def report_markdown(suite: suites.Suite, seed: int, summary: dict, ran: list[str], missing: list[str],
                    failures: list[dict] | None = None, warnings: list[str] | None = None) -> str:
    out = _preamble(suite, seed, ran)
    if missing:
        out += ["", f"Not in this build's method registry, so not run: {', '.join(missing)}."]
    if warnings:
        out += ["", "## Warnings", "", *(f"- {w}" for w in warnings)]
    if failures:
        out += _failures(failures)
    out += _claims(suite, summary)
    out += _sections(suite, summary)
    out += READING
    return "\n".join(out)


def _preamble(suite: suites.Suite, seed: int, ran: list[str]) -> list[str]:
    """The title, how the report was made, and every method with its baselines."""
    kind = ("held out: no parameter of any method was chosen on it" if suite.held_out
            else "not held out: parameters may be chosen on it")
    worlds = list(dict.fromkeys(c.world.partition("#")[0] for sec in suite.sections for c in sec.cases))
    on = f", on the world{'s' * (len(worlds) > 1)} " + ", ".join(f"`{w}`" for w in worlds) if worlds else ""
    made = (f"Made by `armtransfer benchmark --suite {suite.name} --seed {seed}`." if suite.name in suites.SUITES else
            f"Made by `armtransfer benchmark --suite FILE --seed {seed}` from the suite file of `{suite.name}` (its "
            f"whole definition is in results.json){on}.")
    out = [f"# Benchmark `{suite.name}` (version {suite.version})", "",
           f"{made} {suite.description}; {kind}.", "",
           "## Methods and their baselines", "",
           "Every method's gain is measured against the baseline that shares its learner and differs only "
           "in what is transferred; each baseline is run beside it on the same random streams.", ""]
    out.append(markdown_table(["method", "baselines (the first: told nothing)", "what it is"],
                              [[m, (", ".join(baselines_of(m)) or "-") + ("" if m == "none" or registered_baseline(m)
                                                                          else " (default: the registry names none)"),
                                describe(m)] for m in ran]))
    outside = sorted({parse_label(m)[1] for m in ran} - {"sarsa"})
    if outside:
        out += ["", f"`METHOD@LEARNER`: the method run by the outside learner {', '.join(outside)} "
                "(docs/extending.md), on the case's Gymnasium environment with the method's reward term "
                "(`TransferReward`). The harness counts the steps; it learns in chunks of the step cap / "
                f"{lt.CHUNKS}, each followed by one greedy episode (capped at {lt.EVAL_CAP}x the shortest "
                f"path); converged: {lt.EVALS} greedy episodes in a row at most {1 + lt.TOLERANCE:g}x the "
                "shortest path, its steps those at the first of them; otherwise censored at the cap."]
    return out


def _failures(failures: list[dict]) -> list[str]:
    """The runs that failed, and what that leaves out."""
    out: list[str] = []
    out += ["", "## Runs that failed", "",
            f"{sum(f['failed_runs'] for f in failures)} runs failed, so the records below are left out of "
            "everything that follows (method `source`: robot 1's run failed, so every method of that case and "
            "source seed); each method is paired with its baseline over the source seeds both have. The store's "
            "`failed/` keeps each run's traceback, and running the same command again retries them.", ""]
    out.append(markdown_table(["section", "case", "source seed", "method", "runs failed", "first error"],
                              [[f["section"], f["label"], str(f["source_seed"]), f["method"],
                                str(f["failed_runs"]), f["error"].replace("|", "\\|")] for f in failures]))
    return out


def _claims(suite: suites.Suite, summary: dict) -> list[str]:
    """Every comparison's claim, the controls', the strata's and the source seeds' effect."""
    out: list[str] = []
    out += ["", "## Claims", ""]
    for section in suite.sections:
        for name, against in summary[section.name]["pooled"].items():
            for ab in against.values():
                out.append("- " + sentence(name, ab, section.name))
    for section in suite.sections:
        control = control_text(section.name, summary[section.name]["pooled"])
        if control:
            out.append("- " + control)
    for section in suite.sections:
        stratum = summary[section.name].get("with_trajectory")
        if stratum:
            out.append("- " + stratum_text(section.name, stratum))
    out += ["", seed_effect_text(suite, summary)]
    return out


def _sections(suite: suites.Suite, summary: dict) -> list[str]:
    """Each section: its protocol, figures and each case's table."""
    out: list[str] = []
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
            if case.get("source_failures") and sec.get("with_trajectory", {}).get("told_nothing"):
                out.append(f"\nRobot 1 did not converge on {case['source_failures']} of "
                           f"{len(case['optimal_per_seed'])} source seeds: there every method that needs a "
                           "trajectory learned as its baseline told nothing.")
    return out


READING = ["", "## How to read this report", "",
            "- Every claim states, in this order: the good path (steps until the greedy path was at most "
            "ceil(quality x the target's shortest path) steps long and stayed so to the end of the trial; a trial "
            "ends only on a settled good path, so one that settles on a worse path runs on to its episode or step "
            "cap, and one not good at its end counts at the step cap), with the settled quality of the method's and "
            "the baseline's trials beside it (the first settled greedy path over the shortest: median and worst, "
            "and how many trials ended on a good path); the settled clock (steps until the greedy path first "
            "stopped changing, however long: the old headline, which a learner that explores less can buy with a "
            "worse path), the first exposure (steps until the goal was first reached) and the "
            f"transfer ratio (the share of the baseline's steps over the first {HORIZON} episodes that the method "
            "saves; a converged trial goes on at its greedy length). Each is a time until an event: a trial that "
            "did not get there within the cap is censored there, never given a made-up value.",
            "- Against a baseline: trial i of the method and of its baseline share a random stream, so they are "
            "paired; the factor is baseline / method (above 1 the method is faster), a geometric mean over cases, "
            "then source seeds, then trials. A pair capped in both is a tie: counted, left out of the factor. "
            "A pair capped in one gives a bound, counted. The 95% interval is a hierarchical bootstrap-t "
            "(cases, then seeds, then trials resampled; the union of its equal-tailed and symmetric intervals, "
            "which covers at least 93% on normal, heavy-tailed and skewed data in simulation), made only from at "
            f"least {MIN_UNITS} top-level units (cases; source seeds for one case): with fewer it says 'too few'. "
            "A verdict ('faster', 'slower') needs at least "
            f"{suites.MIN_SEEDS_FOR_CLAIM} source seeds and a p-value below 5% after Holm's correction over every "
            "verdict of the report (small p-values come from 200,000 resamples, fine enough for that correction); "
            "otherwise the claim says which factors it could have detected at 80% power, and where the unadjusted "
            "interval excludes 1 it says that Holm's correction is why there is no verdict.",
            "- Control: `lazy` is `plan` with every untried move valued lower: told nothing, it explores less. "
            "A headline it wins against `plan` could be bought by exploring less; the good-path clock must not "
            "rank it ahead.",
            "- KM median: the Kaplan-Meier median over every trial ('> cap' where the curve never falls to one "
            "half); its interval resamples whole source seeds. Failed: trials that never reached the goal within "
            "the cap. Success in budget: trials that reached it within the budget. Seed share: the share of the "
            "variance of log first exposure that lies between source seeds.",
            ""]
"""How to read the report: the closing section, the same for every suite."""


def describe(name: str) -> str:
    """What a record's method is: the method's description, and its learner's when not the built-in."""
    method, learner = parse_label(name)
    if learner == "sarsa":
        return methods.get(method).description
    found = LEARNERS.get(learner)
    text = "no transfer" if method == "none" else methods.get(method).description  # none's is Algorithm 1's
    return text + f"; learned by {learner}" + (f" ({found.description})" if found is not None else "")


def seed_effect_text(suite: suites.Suite, summary: dict) -> str:
    """How much of the spread is the source seeds' (one line), and the seeds whose robot 1 did
    not converge (kept, and every method that needs a trajectory learned there as its baseline)."""
    shares = [e["seed_share"] for s in suite.sections for c in summary[s.name]["cases"]
              for e in c["methods"].values() if e.get("seed_share") is not None]
    failed = [(s.name, c["label"], c.get("source_failures", 0)) for s in suite.sections
              for c in summary[s.name]["cases"] if c.get("source_failures")]
    text = ("Seed effect: the share of the variance of log first exposure that lies between source seeds "
            + (f"has median {float(np.median(shares)):.2f} (range {min(shares):.2f}-{max(shares):.2f}) over "
               f"{len(shares)} case x method cells." if shares else "could not be estimated (too few trials per seed)."))
    seeds = sum(s.source_seeds * len(s.cases) for s in suite.sections)
    n_failed = sum(k for _, _, k in failed)
    if not n_failed:
        return text + f" Robot 1 converged and handed a trajectory over on all {seeds} (case, source seed) pairs."
    told = any(summary[s.name].get("with_trajectory", {}).get("told_nothing") for s in suite.sections)
    text += (f" Robot 1 did not converge for {n_failed} of {seeds} (case, source seed) pairs; they are kept and "
             + ("every method that needs a trajectory learned on them as its baseline told nothing (with nothing "
                "handed over, robot 2 learns as it would without transfer)" if told else
                "every method that needs a trajectory counts as failed on them")
             + (": " + "; ".join(f"{sec} {label}: {k}" for sec, label, k in failed) if failed else "") + ".")
    return text

"""report.md of ``armtransfer reproduce``, written from the dict ``reproduce.run_all`` returns.

Every sentence that states a result is built from that run's numbers; the paper's numbers
(``paper``) stand beside ours with our 95% intervals.
"""

from __future__ import annotations

from armtransfer.experiments import beyond, paper
from armtransfer.experiments.lazy import scipy_stats
from armtransfer.experiments.reports import calibrated_report
from armtransfer.experiments.tables import fmt_ci, fmt_mean, fmt_num, markdown_table
from armtransfer.learning.mapping import ActionMapping
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.worlds.layout import ROOMS

TASKS = (1, 2, 3, 4)
TOP_ENTRIES = 12


def mapping_protocol_text(mapping_from: str) -> str:
    learned = ("the greedy path of ONE converged trial of the task (the first in trial order), as the paper"
               if mapping_from == "single" else "every converged trial's greedy path (pooled)")
    return (
    "Protocol as the paper: tasks 1, 2, 3, 4 in this order; the mapping learned on task 1 is used on "
    "task 2, the one accumulated over tasks 1-2 on task 3, and so on. Each task's trials all use the "
    f"mapping of the tasks before it; afterwards the mapping is updated from {learned}. A key is learned between every two matched states (same cell) of the transferred "
    "trajectory and the converged greedy path, the shorter target sequence wins. On a later task, a "
    "robot at a trajectory cell whose upcoming key is mapped runs the mapped sequence as a macro "
    "with probability 1 - epsilon, during the exploration phase (until the goal is first reached; "
    "offered in every episode, macros keep the robot from ever trying the other actions along the "
    "path, so the greedy path does not converge: `tests/test_mapping.py` shows it). "
    "Method = pseudo rewards + macros."
    )


def fig7_caption(fig: dict | None) -> str:
    if fig is None:
        return "No converged trial used a macro, so there is no Fig. 7 analog."
    return (
        f"Fig. 7 analog: task {fig['task']}, coarse -> fine, trial {fig['trial']} (the converged trial with "
        f"the largest mapped share, {100 * fig['mapped_fraction']:.1f}% of its {len(fig['target_cells']) - 1} "
        "steps). Dashed: the coarse robot's transferred trajectory; solid: the fine robot's converged "
        "greedy path; thick: fragments equal to the macro available where they start."
    )



def _cell(mean: float | None, ci: list[float] | None, digits: int = 1) -> str:
    return f"{fmt_num(mean, digits)} {fmt_ci(ci, digits)}"


def _steps(entry: dict, digits: int = 1) -> str:
    """Exploration steps: mean (≥ when some trials never reached the goal) [CI], reached k/n."""
    ex = entry["exploration_steps"]
    tail = "" if entry.get("reached", len(ex)) == len(ex) else f" (reached {entry['reached']}/{len(ex)})"
    return f"{fmt_mean(entry, digits)} {fmt_ci(entry['ci95'], digits)}{tail}"


def _paper(x: float | None, digits: int = 1) -> str:
    return "NA" if x is None else f"{x:,.{digits}f}"


CANNOT_TELL = "cannot tell"


def detectable_difference(ci: list[float], power: float = 0.8) -> float:
    """The smallest difference from the paper's value that an estimate with this 95% interval
    detects with ``power`` (two-sided, 5%): (z_0.975 + z_power) standard errors, the standard
    error read off the interval's half-width."""
    stats = scipy_stats()
    z = float(stats.norm.ppf(0.975))
    return (z + float(stats.norm.ppf(power))) * (ci[1] - ci[0]) / 2 / z


def _verdict(ours: float | None, ci: list[float] | None, theirs: float | None) -> str:
    """Compare our improvement with the paper's: better / worse when our 95% interval excludes
    its value; otherwise the run cannot tell, and says how large a difference it could detect
    (an interval that holds the paper's value is no evidence of agreement)."""
    if ours is None or theirs is None:
        return ""
    if ci is None:
        return f"{CANNOT_TELL} (no interval)"
    if ci[0] <= theirs <= ci[1]:
        return f"{CANNOT_TELL} (80% power only for differences over {detectable_difference(ci):.0f} points)"
    return "better than paper" if ours > theirs else "**worse than paper**"


def table_ii_markdown(res: dict, paper_table: dict, title: str) -> str:
    header = ["task", "distance", "A paper", "A ours [95% CI]", "B paper", "B ours [95% CI]",
              "C paper %", "C ours % [95% CI]", "vs paper"]
    rows = []
    for t in TASKS:
        r = res[t]["results"]
        p = paper_table[t]
        rows.append([
            str(t),
            str(res[t]["distance"]),
            _paper(p["A"]),
            _steps(r["none"]),
            _paper(p["B"]),
            _steps(r["pseudo"]),
            _paper(p["C"], 2),
            _cell(r["pseudo"]["improvement_percent"], r["pseudo"]["improvement_ci95"]),
            _verdict(r["pseudo"]["improvement_percent"], r["pseudo"]["improvement_ci95"], p["C"]),
        ])
    return f"### {title}\n\n" + markdown_table(header, rows)


def table_iv_markdown(rows: dict) -> str:
    header = ["trajectory", "length (cells) paper", "length (cells) ours", "A paper", "A ours [95% CI]",
              "B paper %", "B ours % [95% CI]", "C paper", "C ours [95% CI]", "D paper %", "D ours %"]
    out = []
    base = rows["optimal"]["results"]["none"]
    p0 = paper.TABLE_IV["no transfer"]
    out.append(["no transfer", "NA", "NA", _paper(p0["A"]), _steps(base), "NA", "",
                _paper(p0["C"]), _cell(base["greedy_mean"], base["greedy_ci95"]), "NA", ""])
    for name, row in rows.items():
        r = row["results"]["pseudo"]
        p = paper.TABLE_IV[name]
        out.append([
            name,
            str(p["distance"]),
            str(row["trajectory_cells"]),
            _paper(p["A"]),
            _steps(r),
            _paper(p["B"], 2),
            _cell(r["improvement_percent"], r["improvement_ci95"]),
            _paper(p["C"]),
            _cell(r["greedy_mean"], r["greedy_ci95"]),
            _paper(p["D"], 2),
            fmt_num(r["greedy_improvement_percent"]),
        ])
    return (
        "### Table IV: task 2, coarse -> fine, different transferred trajectories\n\n"
        + markdown_table(header, out)
        + "\n\nA: exploration steps with transfer; B: improvement over no transfer; C: greedy steps "
        "of the converged policy; D: improvement of C. Our sets are the coarse robot's shortest "
        "paths through waypoints "
        + ", ".join(f"{k}: {v}" for k, v in paper.TABLE_IV_WAYPOINTS.items() if v)
        + " (set 2 enters room 2 and comes back: a loop). Lengths: "
        + "; ".join(f"{name} ours {row['trajectory_cells']} cells ({row['trajectory_length']} coarse steps) vs "
                    f"the paper's {paper.TABLE_IV[name]['distance']}" for name, row in rows.items())
        + "." + _greedy_room(rows)
    )


def _greedy_room(rows: dict) -> str:
    """How much column D could gain at all: no transfer's greedy length against the optimum."""
    base = rows["optimal"]["results"]["none"]
    d = rows["optimal"]["distance"]
    if base["greedy_mean"] is None or not d:
        return ""
    room = 100.0 * (base["greedy_mean"] - d) / base["greedy_mean"]
    return (f" Without transfer our converged greedy path is {base['greedy_mean']:.1f} steps against the "
            f"optimal {d} (the paper's: {paper.TABLE_IV['no transfer']['C']:g}), so D can gain at most "
            f"{room:.1f}% here.")


def wind_markdown(res: dict) -> str:
    header = ["task", "no transfer [95% CI]", "transfer [95% CI]", "improvement % [95% CI]", "converged"]
    rows = []
    for t in TASKS:
        r = res[t]["results"]
        conv = r["pseudo"]["converged"]
        rows.append([
            str(t),
            _steps(r["none"]),
            _steps(r["pseudo"]),
            _cell(r["pseudo"]["improvement_percent"], r["pseudo"]["improvement_ci95"]),
            f"{sum(conv)}/{len(conv)}",
        ])
    return (
        f"### Wind (section IV.C, Fig. 6): coarse -> fine, wind {paper.WIND}\n\n"
        + markdown_table(header, rows)
        + "\n\nThe paper gives Fig. 6 only as a chart (not in its text), so there are no numbers to set beside these."
    )


def _entries_used(r: dict) -> str:
    return f"{r['entries_before']}"


def _mapping_rows(res: dict, protocol: str, table: str, paper_table: dict, improvement_col: str,
                  columns: list[str]) -> list[list[str]]:
    """The rows of a mapping table (Table II D-F or V D-E): every cell by name, then
    ``columns`` picks and orders them. ``improvement_col`` is the paper's column that holds
    the improvement of D (F in Table II, E in Table V)."""
    rows = []
    for t in TASKS:
        r = res[protocol]["tasks"][t]
        p = paper_table[t]
        mapped = (_cell(r["mapped_percent_mean"], r["mapped_percent_ci95"])
                  if r["mapped_percent_mean"] is not None else "NA")
        cells = {
            "task": str(t),
            "B ours": fmt_mean(res[table][t]["results"]["pseudo"]),
            "D paper": _paper(p["D"]),
            "D ours": _steps(r),
            "E paper": _paper(p["E"], 2),
            "F paper": _paper(p.get("F"), 2),
            "mapped": mapped,
            "improvement": _cell(r["improvement_percent"], r["improvement_ci95"]),
            "verdict": _verdict(r["improvement_percent"], r["improvement_ci95"], p[improvement_col]),
            "entries": _entries_used(r),
        }
        rows.append([cells[c] for c in columns])
    return rows


def table_ii_mapping_markdown(res: dict) -> str:
    header = ["task", "B ours (transfer)", "D paper", "D ours [95% CI]", "E paper %", "E ours % [95% CI]",
              "F paper %", "F ours % [95% CI]", "F vs paper", "entries used"]
    rows = _mapping_rows(res, "mapping_coarse_fine", "table_ii", paper.TABLE_II, "F",
                         ["task", "B ours", "D paper", "D ours", "E paper", "mapped", "F paper", "improvement",
                          "verdict", "entries"])
    return (
        "### Table II D-F: coarse -> fine with action sequence mapping (tasks 1 -> 2 -> 3 -> 4)\n\n"
        + markdown_table(header, rows)
        + "\n\nD: exploration steps with transfer and mapping; E: share of the converged greedy path's "
        "steps that lie in a segment equal to a macro available on that task; F: improvement of D over "
        "no transfer (A of the table above). Task k uses the mapping learned on tasks 1..k-1 (\"entries "
        "used\"); task 1 has none, so D equals B there and E is NA, as in the paper."
    )


def table_v_mapping_markdown(res: dict) -> str:
    header = ["task", "B ours (transfer)", "D paper", "D ours [95% CI]", "E paper %", "E ours % [95% CI]",
              "E vs paper", "mapped % of final path [95% CI]", "entries used"]
    rows = _mapping_rows(res, "mapping_fine_coarse", "table_v", paper.TABLE_V, "E",
                         ["task", "B ours", "D paper", "D ours", "E paper", "improvement", "verdict", "mapped",
                          "entries"])
    return (
        "### Table V D-E: fine -> coarse with action sequence mapping (tasks 1 -> 2 -> 3 -> 4)\n\n"
        + markdown_table(header, rows)
        + "\n\nD: exploration steps with transfer and mapping; E: improvement of D over no transfer. "
        "The paper's Table V has no mapped-share column; ours is given for comparison with Table II E."
    )


def table_iii_markdown(protocol: dict, title: str) -> str:
    m = ActionMapping.from_json(protocol["mapping"])
    entries = sorted(m.entries.items(), key=lambda kv: (-kv[1].count, len(kv[0]), kv[0]))
    rows = [[str(n + 1), m.names(k, "source"), m.names(e.target, "target"), str(e.count)]
            for n, (k, e) in enumerate(entries[:TOP_ENTRIES])]
    loops = [(k, e) for k, e in entries if not e.target]
    text = (
        f"### {title}\n\n"
        + markdown_table(["#", f"{m.source} action index sequence", f"{m.target} mapped action sequence", "seen"],
                         rows)
        + f"\n\nThe {TOP_ENTRIES} most often seen of {len(m)} entries after task 4 (\"-\" is the empty "
        "sequence, \"no action\")."
    )
    if loops:
        text += " Keys mapped to no action: " + ", ".join(f"`{m.names(k, 'source')}`" for k, _ in loops[:8]) + "."
    else:
        text += (" No key maps to no action in this run (the hand-made tests check that a loop in a "
                 "transferred trajectory maps to no action).")
    return text


def wind_mapping_markdown(res: dict) -> str:
    header = ["task", "no transfer [95% CI]", "transfer [95% CI]", "transfer + mapping [95% CI]",
              "improvement % [95% CI]", "mapped % of final path", "converged"]
    rows = []
    for t in TASKS:
        w = res["wind"][t]["results"]
        r = res["mapping_wind"]["tasks"][t]
        conv = r["converged"]
        rows.append([
            str(t),
            _steps(w["none"]),
            _steps(w["pseudo"]),
            _steps(r),
            _cell(r["improvement_percent"], r["improvement_ci95"]),
            fmt_num(r["mapped_percent_mean"]),
            f"{sum(conv)}/{len(conv)}",
        ])
    return (
        f"### Action sequence mapping under wind {paper.WIND} (coarse -> fine, tasks 1 -> 2 -> 3 -> 4)\n\n"
        + markdown_table(header, rows)
        + "\n\nUnder wind the mapping is learned the same way, from the converged greedy paths (which "
        "are evaluated without wind), and reused the same way: a gust during a macro moves the robot "
        "one cell to the right and the macro goes on from there (it is abandoned only when the robot "
        "observes that it did not move, after wind: it cannot tell a wall from a gust). The greedy paths "
        "the mapping is learned from, and the converged counts, are rolled out without wind. The paper "
        "gives no numbers for this case."
        + _ratio_sentence(res["mapping_wind"], res["wind"], "under wind")
    )


def _ratio_sentence(protocol: dict, base: dict, where: str) -> str:
    """A measured summary: D as a share of B (transfer alone) on the tasks that had a mapping."""
    ratios = [
        protocol["tasks"][t]["mean"] / base[t]["results"]["pseudo"]["mean"]
        for t in TASKS[1:]
        if protocol["tasks"][t]["mean"] and base[t]["results"]["pseudo"]["mean"]
    ]
    if not ratios:
        return ""
    bound = any(protocol["tasks"][t].get("mean_is_lower_bound") or base[t]["results"]["pseudo"].get("mean_is_lower_bound")
                for t in TASKS[1:])
    return (
        f" Measured here: {where}, on tasks {TASKS[1]}-{TASKS[-1]} the mapping leaves "
        f"{100 * min(ratios):.1f}-{100 * max(ratios):.1f}% of the exploration steps of transfer alone"
        + (" (ratios of means of which some are lower bounds: unreached trials count at the cap)." if bound else ".")
    )


def _vs_paper(rows: list[tuple[int, dict, float | None]]) -> tuple[list[int], list[int], list[int]]:
    """(tasks better than the paper, those this run cannot tell from it, worse), from improvement CIs."""
    better: list[int] = []
    same: list[int] = []
    worse: list[int] = []
    for t, r, theirs in rows:
        v = _verdict(r.get("improvement_percent"), r.get("improvement_ci95"), theirs)
        if v.startswith(CANNOT_TELL):
            same.append(t)
        else:
            {"better than paper": better, "**worse than paper**": worse}.get(v, []).append(t)
    return better, same, worse


def _tasks(ts: list[int]) -> str:
    return ", ".join(str(t) for t in ts) if ts else "none"




def table_i_markdown(res: dict) -> str:
    """Table I: the tasks, with the paper's distance and ours for both robots."""
    header = ["task", "start", "goal", "rooms", "1-cell distance paper", "fine robot ours", "coarse robot ours"]
    rows = []
    for t in TASKS:
        task = TABLE_I[t]
        rows.append([str(t), str(task.start), str(task.goal),
                     f"{ROOMS.room_of(*task.start)} -> {ROOMS.room_of(*task.goal)}",
                     _paper(task.paper_distance, 0), str(res["table_ii"][t]["distance"]),
                     str(res["table_v"][t]["distance"])])
    return ("### Table I: the tasks\n\n" + markdown_table(header, rows)
            + "\n\nDistances are optimal numbers of actions (the coarse robot moves 2 cells per action).")


def alternatives_markdown(res: dict) -> str:
    """The other protocol choices, coarse -> fine, beside the default ones."""
    alt = res["alternatives"]
    kind, other = res["trajectory"], alt["trajectory"]
    header = ["task", f"{kind} trajectory: length", "transfer [95% CI]", "improvement %",
              f"{other} trajectory: length", "transfer [95% CI]", "improvement %"]
    rows = []
    for t in TASKS:
        a, b = res["table_ii"][t], alt["table_ii"][t]
        ra, rb = a["results"]["pseudo"], b["results"]["pseudo"]
        rows.append([str(t), str(a["trajectory_length"]), _steps(ra),
                     _cell(ra["improvement_percent"], ra["improvement_ci95"]),
                     str(b["trajectory_length"]), _steps(rb),
                     _cell(rb["improvement_percent"], rb["improvement_ci95"])])
    mf, mo = res["mapping_from"], alt["mapping_from"]
    header2 = ["task", f"mapping from {mf}: D [95% CI]", "F % [95% CI]", "entries used",
               f"mapping from {mo}: D [95% CI]", "F % [95% CI]", "entries used"]
    rows2 = []
    for t in TASKS:
        a, b = res["mapping_coarse_fine"]["tasks"][t], alt["mapping_coarse_fine"]["tasks"][t]
        rows2.append([str(t), _steps(a), _cell(a["improvement_percent"], a["improvement_ci95"]), _entries_used(a),
                      _steps(b), _cell(b["improvement_percent"], b["improvement_ci95"]), _entries_used(b)])
    diffs = []
    for t in TASKS:
        ra, rb = res["table_ii"][t]["results"]["pseudo"], alt["table_ii"][t]["results"]["pseudo"]
        if ra["mean"] and rb["mean"]:
            diffs.append(rb["mean"] / ra["mean"])
    sentence = ""
    if diffs:
        sentence = (f" With the {other} trajectory, transfer takes {min(diffs):.2f}-{max(diffs):.2f} times "
                    f"the exploration steps it takes with the {kind} one (ratio of means per task).")
    return (
        "### The paper's protocol vs the alternatives (coarse -> fine)\n\n"
        f"Trajectory handed over: **{kind}** (default; the source robot's converged greedy path after "
        "learning without transfer, as the paper) vs **" + other + "**. Improvements are over the same "
        "no-transfer trials (Table II A).\n\n"
        + markdown_table(header, rows) + "\n\n" + sentence.strip() + "\n\n"
        f"Mapping learned from **{mf}** (default; `single` = one converged trial per task, as the paper) "
        f"vs **{mo}** (`pooled` = every converged trial of the task).\n\n"
        + markdown_table(header2, rows2)
    )


def differences_markdown(res: dict) -> list[str]:
    """'Where we differ from the paper': every claim from this run's numbers."""
    out = [
        "- The rooms layout is ours: the paper's Fig. 3 is not in its text. Only the four tasks' "
        "1-cell distances (20, 34, 40, 76) and rooms are matched; door positions, room shapes and "
        "so the difficulty of each task differ.",
        "- The paper does not state alpha, gamma, lambda, epsilon, the rewards or K. We use the "
        "parameters above; none were tuned to match the paper. The trajectory handed over is the "
        + ("source robot's converged greedy path after learning, as the paper"
           if res["trajectory"] == "learned" else "source robot's breadth-first shortest path (not the paper's)")
        + f"; the mapping is learned from {'one converged trial per task, as the paper' if res['mapping_from'] == 'single' else 'every converged trial (pooled; the paper uses one)'}.",
    ]
    for key, ptab, col, name in (("table_ii", paper.TABLE_II, "C", "Table II C (coarse -> fine)"),
                                 ("table_v", paper.TABLE_V, "C", "Table V C (fine -> coarse)")):
        better, same, worse = _vs_paper([(t, res[key][t]["results"]["pseudo"], ptab[t][col]) for t in TASKS])
        line = (f"- {name}, improvement of transfer over no transfer: the paper's value inside our 95% "
                f"interval, so this run cannot tell them apart (each row says how large a difference it "
                f"could detect), on tasks {_tasks(same)}; better on {_tasks(better)}; worse on {_tasks(worse)}.")
        if worse:
            line += (" Where worse: with a negative step reward and Q = 0 the learner already explores "
                     "systematically without transfer, and the pseudo reward, kept below the farming limit "
                     "(step reward + n*K < 0), is smaller than one step's cost, so it barely changes which "
                     "untried action looks best. The paper does not give its reward scale or exploration scheme.")
        out.append(line)
    for key, col, base_key, name in (("mapping_coarse_fine", "F", "table_ii", "Table II F (mapping, coarse -> fine)"),
                                     ("mapping_fine_coarse", "E", "table_v", "Table V E (mapping, fine -> coarse)")):
        ptab = paper.TABLE_II if base_key == "table_ii" else paper.TABLE_V
        better, same, worse = _vs_paper([(t, res[key]["tasks"][t], ptab[t][col]) for t in TASKS if ptab[t][col] is not None])
        out.append(f"- {name}: cannot tell from the paper on tasks {_tasks(same)}; better on {_tasks(better)}; worse on "
                   f"{_tasks(worse)}." + _ratio_sentence(res[key], res[base_key], name.split(", ")[-1].rstrip(")")))
    e_rows = [(t, res["mapping_coarse_fine"]["tasks"][t]["mapped_percent_mean"], paper.TABLE_II[t]["E"])
              for t in TASKS if paper.TABLE_II[t]["E"] is not None]
    lower = [t for t, ours, theirs in e_rows if ours is not None and ours < theirs]
    if e_rows:
        out.append(f"- Column E (mapped share of the final path) is below the paper's on tasks {_tasks(lower)} "
                   f"of {_tasks([t for t, _, _ in e_rows])}. Ours counts only steps in segments that equal, "
                   "exactly, the macro offered where the segment starts; the paper does not define its E precisely.")
    half = []
    for key in ("table_ii", "table_v"):
        for t in TASKS:
            for m in ("none", "pseudo"):
                r = res[key][t]["results"][m]
                if r["mean"] and r["ci95"]:
                    half.append((r["ci95"][1] - r["ci95"][0]) / 2 / r["mean"])
    if half:
        out.append(f"- The paper reports means of {paper.PAPER_TRIALS} trials without intervals; with "
                   f"{res['trials']} trials our 95% half-widths are {100 * min(half):.0f}-{100 * max(half):.0f}% "
                   "of the mean (Tables II and V), so differences smaller than that between our numbers and "
                   "the paper's mean little. For a tighter estimate of one task, run `armtransfer rooms "
                   "--task N --trials 300 --no-controls`.")
    censored = [(key, t, m) for key in ("table_ii", "table_v", "wind") for t in TASKS
                for m, r in res[key][t]["results"].items() if r.get("mean_is_lower_bound")]
    if censored:
        out.append("- Some trials never reached the goal within the step cap ("
                   + ", ".join(f"{k} task {t} {m}" for k, t, m in censored[:6])
                   + (", ..." if len(censored) > 6 else "")
                   + "); they count at the cap and those means are lower bounds (≥).")
    return out


def report_markdown(res: dict, figures: dict[str, str]) -> str:
    cfg = res["config"]
    ks = sorted({round(r["results"]["pseudo"]["K"], 6) for key in ("table_ii", "table_v")
                 for r in res[key].values() if "K" in r["results"]["pseudo"]})
    lines = [
        "# Reproduction of Lakshmanan & Ravindran (2010) on our rooms world",
        "",
        f"{res['trials']} trials per cell (the paper: {paper.PAPER_TRIALS}), seed {res['seed']}. "
        "Exploration steps = steps until the goal is first reached. Every trial counts: one that never "
        f"reaches the goal within {cfg['max_total_steps']:,} steps counts at that cap, and its mean is "
        "then a lower bound (≥, with reached k/n). Means with 95% percentile-bootstrap intervals over trials "
        "(they stay within the steps observed); improvement intervals by the delta method on the log of the "
        "ratio of means, on paired trials (all methods share the random stream of trial i: common random "
        "numbers).",
        "",
        f"Learner{' (preset ' + res['preset'] + ')' if res.get('preset', 'default') != 'default' else ''}: SARSA(lambda), alpha {cfg['alpha']}, gamma {cfg['gamma']}, lambda {cfg['lam']}, "
        f"epsilon {cfg['epsilon']}, step reward {cfg['step_reward']}, goal reward {cfg['goal_reward']}, "
        f"Q = 0 initially. K = 'auto' (half the farming bound -step_reward/n): "
        f"{', '.join(f'{k:g}' for k in ks) if ks else 'n/a'} in this run. Transferred trajectory: "
        f"**{res['trajectory']}**; mapping learned from **{res['mapping_from']}** trial(s) per task.",
        "",
        table_i_markdown(res),
        "",
        f"![Fig. 3 analog]({figures['fig3']})",
        "",
        "Fig. 3 analog: the rooms layout with Table I's starts (squares) and goals (stars).",
        "",
        table_ii_markdown(res["table_ii"], paper.TABLE_II, "Table II A-C: coarse (larger) -> fine robot"),
        "",
        f"![Fig. 4 analog]({figures['fig4']})",
        "",
        table_ii_markdown(res["table_v"], paper.TABLE_V, "Table V A-C: fine -> coarse (larger) robot"),
        "",
        f"![Fig. 5 analog]({figures['fig5']})",
        "",
        "Fig. 5 analog: fine -> coarse, no transfer, transfer, and transfer + action sequence mapping.",
        "",
        table_iv_markdown(res["table_iv"]),
        "",
        wind_markdown(res["wind"]),
        "",
        f"![Fig. 6 analog]({figures['fig6']})",
        "",
        "## Action sequence mapping (section III.C)",
        "",
        mapping_protocol_text(res["mapping_from"]),
        "",
        table_ii_mapping_markdown(res),
        "",
        table_v_mapping_markdown(res),
        "",
        table_iii_markdown(res["mapping_coarse_fine"], "Table III analog: coarse -> fine mapping after tasks 1-4"),
        "",
        table_iii_markdown(res["mapping_fine_coarse"], "Table III analog: fine -> coarse mapping after tasks 1-4"),
        "",
        f"![Fig. 7 analog]({figures['fig7']})",
        "",
        fig7_caption(res["mapping_coarse_fine"]["figure"]),
        "",
        wind_mapping_markdown(res),
        "",
        alternatives_markdown(res),
        "",
        "## Beyond the paper",
        "",
        "These runs transfer the coarse robot's shortest path (not the learned one).",
        "",
        beyond.methods_markdown(res["methods"]),
        "",
        res["oracle_text"],
        "",
        f"![All methods]({figures['methods']})",
        "",
        beyond.controls_markdown(res["methods"], res["config"]["max_total_steps"]),
        "",
        beyond.metrics_markdown(res["methods"]),
        "",
        "## Where we differ from the paper, and why",
        "",
        *differences_markdown(res),
        *(["", *calibrated_report.section_markdown(res)] if "calibrated" in res else []),
    ]
    return "\n".join(lines) + "\n"

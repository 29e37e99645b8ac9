"""Robot 2 in its continuous configuration space: step rate, and Table I learned from the pseudo reward.

    python benchmarks/bench_continuous.py --out DIR            # the measured run (about 15-25 minutes)
    python benchmarks/bench_continuous.py --fast --out DIR     # a smoke run (seconds; the source's
                                                               # shortest path instead of its learned one)

(a) Step rate, one core, each arm of ``--arms``' continuous arm (``ik.continuous``) with the linear learner
(``learning.linear``, 8 tilings): each round runs the learner on Table I task 1 without transfer
for ``--rate-steps`` steps, and, in the same round, the bare loop the arm cannot do without
(MuJoCo's ``mj_kinematics`` + ``mj_collision`` on the same model, as many calls) and the arm
alone (random actions, no learner). Reported: medians over the rounds and the ratio of each to
the bare loop.

(b) Table I as continuous targets: for each pair (source robot -> continuous target arm) and
task, ``--seeds`` source seeds; source seed k hands over the source's learned trajectory
(``experiment.source_trajectory("learned", ..., seed=k)``) and the target runs one trial per
method with the generator ``trial_rng(k, 0)`` (common random numbers: the methods meet the
same stream). Reported per method: first exposure (steps of the first episode; a trial that
never reaches the goal is censored at the step cap and counted), its mean with a bootstrap 95%
interval (a lower bound when any is censored), worst case, failure rate (Wilson 95%), the
Kaplan-Meier median; success rate (converged within the caps); steps to convergence (censored at
the cap); the area under the learning curve (steps of the first ``--episodes`` episodes, a trial
that stopped early padded with its greedy length, ``learning_metrics.curve``); and pseudo's paired
improvement in first exposure over none.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from armtransfer import checks, script
from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import continuous as runs
from armtransfer.experiments.stats import learning_metrics, metrics, survival
from armtransfer.ik.continuous import MAX_NOISE, NOISE_CLIP
from armtransfer.experiments.experiment import source_trajectory, trial_rng
from armtransfer.learning import linear
from armtransfer.learning.config import LearnerConfig
from armtransfer.tasks.arms import robot as tabular_robot
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.continuous import continuous_arm

ROOT = Path(__file__).resolve().parents[1]
METHODS = ("none", "pseudo")
BYO = "planar5"
"""The bring-your-own arm: ``tests/menagerie_like.py``'s Menagerie-style planar 5-joint arm file
(meshes in a folder, a stylus body for its tool point), mounted where that module suggests."""


def byo_arm(directory: Path, fast: bool, noise: float = 0.0):
    sys.path.insert(0, str(ROOT / "tests"))
    import menagerie_like  # the project's own Menagerie-style arm files (tests/)

    xml = menagerie_like.planar5_straight(directory)
    opts = menagerie_like.SUGGESTED[BYO]
    return (continuous_arm(None, xml_path=xml, joint_step=0.35, noise=noise, **opts),
            f"{BYO} arm file (joint step 0.35)")


PAIRS = ("planar2:joint->planar3", "ur5e_like:cartesian->planar2", f"planar2:joint->{BYO}")
"""The pairs measured, by the names ``--pairs`` takes."""


def pairs(directory: Path, fast: bool, chosen: list[str], noise: float = 0.0) -> list[tuple[str, str, Any]]:
    """(source spec, target name, target arm) of each chosen pair."""
    out = []
    for name in chosen:
        source, target = name.split("->")
        if target == BYO:
            arm, label = byo_arm(directory, fast, noise)
            out.append((source, label + " (continuous)", arm))
        else:
            out.append((source, f"{target}:joint (continuous)", continuous_arm(target, noise=noise)))
    return out


# ----------------------------------------------------------------------------- (a) step rate


RATE_ARMS = ("planar3", "gen:planar:6:0", "ur5e_like", "panda_like.xml")
"""The arms whose step rate is measured: planar3, a generated 6-joint planar arm (hashed tiles:
its dense tiles would be 2.7e7 features), the spatial ``ur5e_like`` (``ik.continuous3d``) and
a 7-joint arm file, ``panda_like``'s MJCF file loaded as a file with its mount (spatial arms:
hashed tiles, ``experiments.continuous.approximation_for``)."""
HASHED_BITS = 16


def rate_arm(spec: str):
    """The continuous arm named by ``spec`` (``panda_like.xml``: the built-in panda_like's file
    loaded by path with its mount and tool point)."""
    if spec == "panda_like.xml":
        from armtransfer.models import ARMS

        info = ARMS["panda_like"]
        return continuous_arm(None, xml_path=info.xml_path, tip_site=info.tip_site, base_pos=info.mount_pos,
                              base_yaw=info.mount_yaw)
    return continuous_arm(spec)


def _visited(arm, goal: int, coding, steps: int) -> np.ndarray:
    """The whole configurations the arm is at after each of ``steps`` steps of the learner
    (Python loop, a fixed seed): what the bare loop runs MuJoCo on."""
    out = np.empty((steps, arm.model.nq))
    k = [0]
    move = arm.move

    class Recording:
        n_actions = arm.n_actions
        q = arm.q

        def reset(self):
            return arm.reset()

        def key(self):
            return arm.key()

        def move(self, a):
            v = move(a)
            if k[0] < steps:
                out[k[0]] = arm.data.qpos
                k[0] += 1
            return v

    config = LearnerConfig(max_episodes=1_000_000, max_total_steps=steps, max_episode_steps=steps)
    linear.learn(Recording(), goal, coding, config, np.random.default_rng(12345))
    return out[:k[0]]


def _arm_rates(spec: str, rounds: int, steps: int, approx: runs.Approximation) -> dict:
    """One arm's rates, every loop in each round: bare MuJoCo (``mj_kinematics`` +
    ``mj_collision`` on a data of the arm's model, from Python, at the configurations the
    learner visits), the arm alone, the arm with the learner (the compiled episode,
    ``experiments.fastloop``, and the Python loop), the two Gymnasium environments."""
    import mujoco

    from armtransfer.experiments import fastloop
    from armtransfer.tasks.continuous_env import ContinuousArmRoomsEnv

    arm = rate_arm(spec)
    start, goal = TABLE_I[1].cells(arm.layout)
    arm.place(start)
    if getattr(arm, "levels", 0) and not approx.table_bits:
        approx = runs.approximation_for(arm)
    if arm.dof > 4 and not approx.table_bits:
        approx = dataclasses.replace(approx, table_bits=HASHED_BITS)
    coding = approx.coding(arm)
    fast = fastloop.episode_steps(arm)
    config = LearnerConfig(max_episodes=1_000_000, max_total_steps=steps, max_episode_steps=steps)
    for by in (fast, None):  # compile (or load) the kernels first
        linear.learn(arm, goal, coding, LearnerConfig(max_total_steps=2000), np.random.default_rng(0), steps_by=by)
    qs = _visited(arm, goal, coding, steps)
    env = ContinuousArmRoomsEnv(rate_arm(spec), TABLE_I[1])
    box = ContinuousArmRoomsEnv(rate_arm(spec), TABLE_I[1], actions="box")
    m, d = arm.model, mujoco.MjData(arm.model)
    acts = np.random.default_rng(0).integers(0, arm.n_actions, steps).tolist()
    turns = list(np.random.default_rng(0).uniform(-1.0, 1.0, (steps, arm.dof)).astype(np.float32))
    for e, a in ((env, acts[0]), (box, turns[0])):  # compile (or load) the environments' moves first
        e.reset(seed=0)
        e.step(a)
    per: dict[str, list[float]] = {k: [] for k in ("bare", "arm", "learner", "learner_python", "env", "env_box")}
    rows = list(qs)
    for r in range(rounds):
        qpos = d.qpos
        kin, col = mujoco.mj_kinematics, mujoco.mj_collision
        t = time.perf_counter()
        for q in rows:
            qpos[:] = q
            kin(m, d)
            col(m, d)
        per["bare"].append(len(rows) / (time.perf_counter() - t))
        arm.reset()
        move = arm.move
        t = time.perf_counter()
        for a in acts:
            move(a)
        per["arm"].append(steps / (time.perf_counter() - t))
        for key, by in (("learner", fast), ("learner_python", None)):
            moves = arm.moves
            t = time.perf_counter()
            linear.learn(arm, goal, coding, config, np.random.default_rng(r), steps_by=by)
            per[key].append((arm.moves - moves) / (time.perf_counter() - t))
        for key, e, actions in (("env", env, acts), ("env_box", box, turns)):
            e.reset(seed=r)
            step = e.step
            t = time.perf_counter()
            for a in actions:
                if step(a)[2]:
                    e.reset()
            per[key].append(steps / (time.perf_counter() - t))
    ratios = {k: [v / b for v, b in zip(per[k], per["bare"])] for k in per if k != "bare"}
    med = {k: statistics.median(v) for k, v in per.items()}
    return {"dof": arm.dof, "joints": int(arm.model.nq), "compiled": fast is not None, "per_round": per,
            "median_steps_per_s": med, "ratio_to_bare": {k: statistics.median(v) for k, v in ratios.items()},
            "ratio_per_round": ratios, "features": coding.size, "tilings": approx.tilings,
            "table_bits": approx.table_bits}


def step_rate(rounds: int, steps: int, approx: runs.Approximation, arms=RATE_ARMS) -> dict:
    """The step rates of each of ``arms`` (:func:`_arm_rates`), one core; also planar3's under
    the old keys."""
    out = {spec: _arm_rates(spec, rounds, steps, approx) for spec in arms}
    first = out[arms[0]]
    return {"rounds": rounds, "steps_per_round": steps, "arms": out, "per_round": first["per_round"],
            "median_steps_per_s": first["median_steps_per_s"], "ratio_to_bare": first["ratio_to_bare"],
            "features": first["features"], "tilings": first["tilings"]}


# ----------------------------------------------------------------------------- (b) Table I


def wilson(k: int, n: int) -> list[float]:
    from scipy import stats

    ci = stats.binomtest(k, n).proportion_ci(0.95, method="wilson")
    return [float(ci.low), float(ci.high)]


def method_stats(trials: list, cap: int, horizon: int) -> dict:
    first = [t.exploration_steps for t in trials]
    n = len(trials)
    failed = sum(v is None for v in first)
    fx = metrics.exploration_stats(first, cap)
    conv = [t.total_steps for t in trials]
    cs = metrics.exploration_stats(conv, cap)
    km = survival.kaplan_meier(first, cap)
    areas = [float(learning_metrics.curve(t.episode_steps, t.greedy_steps, horizon).sum()) for t in trials]
    area_mean, area_ci = metrics.mean_ci(areas)
    converged = sum(bool(t.converged) for t in trials)
    return {
        "n": n, "first_exposure": first, "first_mean": fx["mean"], "first_ci95": fx["ci95"],
        "first_mean_is_lower_bound": fx["mean_is_lower_bound"], "first_worst": float(max(metrics.censor(first, cap))),
        "first_failure_rate": failed / n, "first_failure_ci95": wilson(failed, n), "first_km_median": km["median"],
        "success_rate": converged / n, "success_ci95": wilson(converged, n),
        "convergence_steps": conv, "convergence_mean": cs["mean"], "convergence_ci95": cs["ci95"],
        "convergence_mean_is_lower_bound": cs["mean_is_lower_bound"],
        "auc": areas, "auc_mean": area_mean, "auc_ci95": area_ci,
    }


def table_one(seeds: int, config: LearnerConfig, source_config: LearnerConfig, approx: runs.Approximation,
              directory: Path, fast: bool, tasks: list[int], chosen: list[str], noise: float = 0.0) -> list[dict]:
    out = []
    for source_spec, target_name, arm in pairs(directory, fast, chosen, noise):
        source = tabular_robot(source_spec)
        for task in tasks:
            start, goal = TABLE_I[task].cells(arm.layout)
            arm.place(start)
            t0 = time.perf_counter()
            moves0 = arm.moves
            per_method: dict[str, list] = {m: [] for m in METHODS}
            for k in range(seeds):
                traj = source_trajectory("optimal" if fast else "learned", source, start, goal, source_config, k)
                for m in METHODS:
                    res = runs.run_method(m, arm, goal, [traj], 1, k, config, approx=approx)
                    per_method[m].append(res.trials[0])
            stats_ = {m: method_stats(v, config.max_total_steps, config.max_episodes) for m, v in per_method.items()}
            imp = metrics.paired_improvement([t.exploration_steps for t in per_method["none"]],
                                             [t.exploration_steps for t in per_method["pseudo"]],
                                             config.max_total_steps, paired=True)
            seconds = time.perf_counter() - t0
            out.append({"source": source_spec, "target": target_name, "task": task, "methods": stats_,
                        "pseudo_vs_none_first_exposure": {k: imp[k] for k in ("percent", "ci95", "design", "censored")},
                        "seconds": seconds, "steps_per_s": (arm.moves - moves0) / seconds})
            print(f"  {source_spec} -> {target_name}, task {task}: {seconds:.0f} s", file=sys.stderr, flush=True)
    return out


# ----------------------------------------------------------------------------- report


def _n(x, digits: int = 0) -> str:
    return "n/a" if x is None else f"{x:,.{digits}f}"


def _ci(ci) -> str:
    return "" if ci is None else f" [{_n(ci[0])}, {_n(ci[1])}]"


def _pct(x) -> str:
    return f"{100 * x:.0f}%"


def markdown(result: dict) -> str:
    rate = result["rate"]
    med = rate["median_steps_per_s"]
    lines = [f"Command: `{result['command']}`; {result['machine']}; {result['date']}; {result.get('load', '')}.",
             "", "Step rate (one core, Table I task 1, medians of "
             f"{rate['rounds']} rounds of {rate['steps_per_round']:,} steps, every loop in every round):", "",
             "| arm | loop | steps/s | ratio to bare MuJoCo (median of per-round ratios) |", "|---|---|---:|---:|"]
    names = {"bare": "bare `mj_kinematics` + `mj_collision`", "arm": "continuous arm alone (random actions)",
             "learner": "arm + linear SARSA(lambda), compiled episode",
             "learner_python": "arm + linear SARSA(lambda), Python loop",
             "env": "`ContinuousArmRooms-v0` step (random actions)",
             "env_box": "`ContinuousArmRoomsBox-v0` step (random actions)"}
    for spec, r in rate["arms"].items():
        med = r["median_steps_per_s"]
        coding = (f"{r['tilings']} tilings, " + (f"hashed, 2^{r['table_bits']}" if r["table_bits"] else "dense")
                  + f", {r['features']:,} features")
        for key, name in names.items():
            ratio = "1" if key == "bare" else f"{r['ratio_to_bare'][key]:.2f}"
            extra = f" ({coding})" if key.startswith("learner") else ""
            lines.append(f"| {spec} ({r.get('joints', r['dof'])} joints, {r['dof']} moved) | {name}{extra} | "
                         f"{_n(med[key])} | {ratio} |")
    lines.append("")
    cfg = result["config"]
    if not result["table_one"]:
        return "\n".join(lines) + "\n"
    lines += [f"Table I, {result['seeds']} source seeds, caps: {cfg['max_total_steps']:,} steps per trial, "
              f"{cfg['max_episodes']} episodes, {cfg['max_episode_steps']:,} steps per episode after the first, "
              f"patience {cfg['patience']}. First exposure: mean [bootstrap 95%] (a lower bound, marked >=, when a "
              "trial is censored), worst, failure rate [Wilson 95%]; success: converged within the caps; "
              "convergence: steps until the greedy path stopped changing (censored at the cap); AUC: steps of the "
              f"first {cfg['max_episodes']} episodes.", "",
              "| pair | task | method | first exposure | worst | failed | KM median | success | convergence | AUC | "
              "pseudo vs none |", "|---|---|---|---|---:|---|---:|---|---|---|---|"]
    for row in result["table_one"]:
        for m, s in row["methods"].items():
            lb = ">= " if s["first_mean_is_lower_bound"] else ""
            clb = ">= " if s["convergence_mean_is_lower_bound"] else ""
            imp = row["pseudo_vs_none_first_exposure"]
            gain = (f"{imp['percent']:+.0f}%{_ci(imp['ci95'])}" if m == "pseudo" and imp["percent"] is not None else "")
            lines.append(
                f"| {row['source']} -> {row['target']} | {row['task']} | {m} | {lb}{_n(s['first_mean'])}"
                f"{_ci(s['first_ci95'])} | {_n(s['first_worst'])} | {_pct(s['first_failure_rate'])} "
                f"[{_pct(s['first_failure_ci95'][0])}, {_pct(s['first_failure_ci95'][1])}] | "
                f"{_n(s['first_km_median'])} | {_pct(s['success_rate'])} | {clb}{_n(s['convergence_mean'])} | "
                f"{_n(s['auc_mean'])} | {gain} |")
    return "\n".join(lines) + "\n"


def survival_figure(result: dict, path: Path) -> None:
    """Kaplan-Meier curves of first exposure, one panel per pair and task, none against pseudo."""
    from armtransfer.experiments.reports import figures

    cap = result["config"]["max_total_steps"]
    panels = []
    for row in result["table_one"]:
        curves = {}
        for m, st in row["methods"].items():
            km = survival.kaplan_meier(st["first_exposure"], cap)
            curves[m] = (km["times"], km["survival"])
        panels.append((f"{row['source']} -> {row['target'].replace(' (continuous)', '')}, task {row['task']}", curves))
    figures.survival_grid(panels, cap, f"First exposure on continuous targets ({result['seeds']} source seeds)", path)


def machine() -> str:
    """The CPU's model and count, memory and Python, as this machine reports them."""
    import os

    model = platform.processor() or "cpu"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
        pages = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        memory = f", {pages / 2**30:.0f} GiB"
    except (OSError, ValueError):
        memory = ""
    return f"{platform.machine()} {model}, {os.cpu_count()} cores{memory}, Python {platform.python_version()}"


def _run(args) -> int:
    out = Path(args.out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise InvalidParameterError(f"--out {str(out)!r} must be an absent or empty directory")
    if args.seeds < 1 or args.rounds < 1 or args.rate_steps < 100:
        raise InvalidParameterError("--seeds and --rounds must be positive and --rate-steps at least 100")
    approx = runs.Approximation(tilings=args.tilings, width=args.width, table_bits=args.table_bits)
    noise = checks.real(args.noise, "--noise (the actuation noise sigma)", 0.0, MAX_NOISE)
    bad = [t for t in args.tasks if t not in TABLE_I] + [p for p in args.pairs if p not in PAIRS]
    if bad:
        raise InvalidParameterError(f"unknown task or pair {bad[0]!r}; valid tasks: {', '.join(map(str, TABLE_I))}; "
                                    f"valid pairs: {', '.join(PAIRS)}")
    chosen = list(dict.fromkeys(args.pairs))
    tasks = list(dict.fromkeys(args.tasks))
    if args.fast:
        config = LearnerConfig(max_episodes=5, max_total_steps=20_000, max_episode_steps=5_000, patience=2)
        tasks, chosen = tasks[:1], chosen[:1]
    else:
        config = LearnerConfig(max_episodes=args.episodes, max_total_steps=args.cap,
                               max_episode_steps=args.episode_cap, patience=args.patience)
    source_config = LearnerConfig()
    load = os.getloadavg()
    print("step rate ...", file=sys.stderr, flush=True)
    arms = [a for a in args.arms if a not in RATE_ARMS]
    if arms:
        raise InvalidParameterError(f"unknown arm {arms[0]!r}; valid arms: {', '.join(RATE_ARMS)}")
    chosen_arms = tuple(dict.fromkeys(args.arms))
    rate = step_rate(args.rounds, args.rate_steps, approx, chosen_arms[:1] if args.fast else chosen_arms)
    table: list[dict] = []
    if not args.rate_only:
        print("Table I ...", file=sys.stderr, flush=True)
        with tempfile.TemporaryDirectory() as tmp:
            table = table_one(args.seeds, config, source_config, approx, Path(tmp), args.fast, tasks, chosen, noise)
    result = {"command": " ".join(["python", "benchmarks/bench_continuous.py", *sys.argv[1:]]),
              "machine": machine(),
              "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "seeds": args.seeds,
              "load": "load average {:.2f} {:.2f} {:.2f} at the start".format(*load),
              "config": config.to_dict(), "approximation": dataclasses.asdict(approx), "noise": noise,
              "rate": rate, "table_one": table}
    out.mkdir(parents=True, exist_ok=True)
    (out / "continuous.json").write_text(json.dumps(result, indent=1, default=float) + "\n")
    text = markdown(result)
    (out / "continuous.md").write_text(text)
    if table:
        survival_figure(result, out / "survival.png")
    print(text)
    return 0


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    p.add_argument("--out", required=True, help="an absent or empty directory for continuous.md and continuous.json")
    p.add_argument("--fast", action="store_true",
                   help="a smoke run: 2 seeds, the first task and pair, tiny caps, the source's shortest path handed over")
    p.add_argument("--rate-only", action="store_true", help="measure the step rate only (a)")
    p.add_argument("--seeds", type=int, default=10)
    p.add_argument("--tasks", type=int, nargs="+", default=list(TABLE_I), help="Table I tasks (default: all)")
    p.add_argument("--pairs", nargs="+", default=list(PAIRS), help=f"pairs (default: all): {', '.join(PAIRS)}")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--rate-steps", type=int, default=100_000)
    p.add_argument("--arms", nargs="+", default=list(RATE_ARMS), help=f"the arms of (a) (default: all): "
                   f"{', '.join(RATE_ARMS)}")
    p.add_argument("--tilings", type=int, default=runs.Approximation().tilings)
    p.add_argument("--width", type=float, default=runs.Approximation().width, help="tile width in joint steps")
    p.add_argument("--table-bits", type=int, default=0, metavar="K",
                   help="hashed tile coding into 2**K features per action (default 0: dense tiles)")
    p.add_argument("--cap", type=int, default=150_000, help="steps per trial at most")
    p.add_argument("--episodes", type=int, default=300)
    p.add_argument("--episode-cap", type=int, default=50_000, help="steps per episode after the first at most")
    p.add_argument("--patience", type=int, default=LearnerConfig().patience)
    p.add_argument("--noise", type=float, default=0.0, metavar="SIGMA",
                   help="the target arm's actuation noise in Table I (each move turns delta * (1 + eps), "
                        f"eps ~ N(0, SIGMA^2) clipped to +-{NOISE_CLIP}; default 0: none)")
    args = p.parse_args(argv)
    if args.fast:
        args.seeds, args.rounds, args.rate_steps = min(args.seeds, 2), min(args.rounds, 2), min(args.rate_steps, 3000)
    return script.run(_run, args)


if __name__ == "__main__":
    script.exit_with(main)

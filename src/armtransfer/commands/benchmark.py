"""armtransfer benchmark: run a fixed, versioned suite into a result store and write one report.

The suite's runs (robot 1's learning per case and source seed, and every trial of every
method) go into the store the sweeps use (``--out``), keyed by content: a run that stops, even
by SIGKILL, loses only the runs under way, and the same command resumes it; ``--workers N``
runs them on N local processes, ``--executor ray`` on Ray (``--address`` for a cluster). When
every run is in, the report is written into the same directory: report.md, results.json (one
record per case, source seed and method, then the statistics; the same seed gives the same
bytes, however and wherever the runs ran), timings.json (the runs' seconds, apart so
results.json stays deterministic) and the figures. ``armtransfer summarize DIR`` writes it
again from the store.
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as _dt
import json
import os
import time
from pathlib import Path

from armtransfer.checks import MAX_COUNT
from armtransfer.commands import common
from armtransfer.commands.sweep import add_executor_arguments, check_executor_options
from armtransfer.errors import InvalidParameterError, PluginError
from armtransfer.experiments import benchmark, learner_trial, suite_files, suites
from armtransfer.experiments.benchmark_runs import execute_recorded as execute
from armtransfer.experiments.run import SourceRun, TrialRun
from armtransfer.experiments.stored_form import leave_out
from armtransfer.experiments.reports import benchmark_report
from armtransfer.experiments.stats import benchmark_stats
from armtransfer.experiments.store import ResultStore, StoreError
from armtransfer.experiments.sweep import Sweep, content_key
from armtransfer.io import check_writable, write_bytes_atomic, write_json_atomic, write_text_atomic
from armtransfer.learning import methods
from armtransfer.learning.learners import BUILTIN, LEARNERS, RUN_TIME, get, parse
from armtransfer.learning.methods import probe_on, refuse_run_time
from armtransfer.parallel.executors import check_reachable, import_ray, run_local, run_ray

HELP = "Compare every method with the baselines that share its learner on a fixed suite, over many source seeds."
EXAMPLE = "armtransfer benchmark --suite fast --out runs/bench-fast"


def add_arguments(p: argparse.ArgumentParser) -> None:
    listing = "; ".join(f"{s.name}{' (held out)' if s.held_out else ''}: {s.description}" for s in suites.SUITES.values())
    p.add_argument("--suite", required=True, metavar="NAME|FILE",
                   help="the suite to run: a built-in one, or a suite file PATH.toml or PATH.json of your own cases on "
                        f"your own world (docs/benchmark.md). Built-in suites: {listing}")
    p.add_argument("--out", default=None,
                   help="result store directory: absent, empty, or this suite and seed's store to resume; the "
                        "report is written into it when every run is in (default runs/benchmark-<suite>-<timestamp>)")
    p.add_argument("--seed", type=common.non_negative_int, default=0, help="random seed, >= 0 (default 0)")
    p.add_argument("--method", nargs="+", default=None, metavar="METHOD",
                   help="run only these methods, each beside its baselines (default: the suite's methods and "
                        "every method of an installed plugin); a method's records are the same bytes either way")
    learned = "; ".join(f"{name}: {lr.description}" for name, lr in LEARNERS.items())
    p.add_argument("--learner", default=None, metavar="NAME[,NAME...]",
                   help="the learners every method runs on, each method beside the baseline the same learner runs "
                        "(an outside learner runs none and the reward-term methods; docs/extending.md); default: the "
                        f"suite's own (sarsa). Learners: {learned}")
    p.add_argument("--quality", type=float, default=None, metavar="Q",
                   help="a good path is at most ceil(Q x the target's shortest path) steps; a trial ends only on a "
                        "settled good path and the headline counts the steps until the greedy path is good and stays "
                        "so (default: the preset's, 1.05)")
    p.add_argument("--run-on", type=float, default=None, metavar="R",
                   help="a trial that settles on a path that is not good runs on at most R times the steps it took "
                        "to settle (default: the preset's, 1.0)")
    common.add_world_argument(p)
    add_executor_arguments(p)
    common.add_preset_argument(p)


def results_bytes(suite: suites.Suite, seed: int, ran: list[str], missing: list[str], records: list[dict],
                  summary: dict, failures: list[dict] | None = None) -> bytes:
    """results.json's bytes: the same for the same suite, seed and build. ``failures``: the
    records left out because a run of theirs failed (``Plan.failures``), listed when there are."""
    data = leave_out({"suite": suite.to_dict(), "seed": seed, "methods": ran, "not_in_registry": missing,
                      "baselines": {m: list(benchmark.baselines_of(m)) for m in ran}, "records": records,
                      "summary": summary, "failed": failures or []}, {"failed": []})
    return (json.dumps(data, indent=1, sort_keys=False) + "\n").encode()


def run(args: argparse.Namespace) -> int:
    suite = suites.named(args.suite)
    refuse_other_world(args, suite)
    check_executor_options(args)
    out = Path(args.out) if args.out else Path("runs") / _dt.datetime.now().strftime(
        f"benchmark-{suite.name}-%Y%m%d-%H%M%S")
    check_writable(out / "sweep.json")  # a name too long, a file in the way: before any arm is compiled
    if args.executor == "ray":
        import_ray()  # say how to install Ray before anything is written
        if args.address:
            check_reachable(args.address)
    wanted = suite.methods
    if not suites.is_builtin(suite) and all(s.methods is not None for s in suite.sections):
        # a suite file's methods: those its sections name (a section may name its own)
        wanted = tuple(dict.fromkeys(m for s in suite.sections for m in s.methods or ()))
    if args.method is not None:
        wanted = tuple(methods.get(m).name for m in args.method)  # a typo lists the valid names
    ran, missing = benchmark.methods_to_run(wanted)
    learners = None
    if args.learner is not None:
        learners = parse(args.learner)  # a typo lists the valid names
    robots = benchmark.Robots({})
    plan = benchmark.plan(suite, args.seed, robots, ran, missing, preset=args.preset, learners=learners,
                          quality=args.quality, run_on=args.run_on)
    # a plugin's fault stops the run here, in one line, before its store is opened
    probe_on(plan.methods, [robots(p.case.target, p.case.world) for p in plan.pairs], args.probe_timeout)
    refuse_run_time(plan.methods, "a benchmark's runs")  # every case's task checked before anything is written
    probe_learners(plan, robots, args.probe_timeout)
    t0 = time.perf_counter()
    store = ResultStore.open_for(out, Sweep(plan.name, plan.spec(), ()))
    try:
        failed = _run_into(store, plan, robots.resolved, args)
        summary = write_report(store, plan)  # under the lock: a summarize waits for the report
    finally:
        store.unlock()  # and its lock file is removed
    print(f"wrote {out / 'report.md'} ({time.perf_counter() - t0:.0f} s)"
          + (f" from the runs that finished; {failed} failed, listed in it and in {out / 'failed'} (with their "
             "tracebacks); run the same command again to retry them" if failed else ""))
    for section in suite.sections:
        for name, against in summary.get(section.name, {}).get("pooled", {}).items():
            for ab in against.values():
                print(benchmark_report.sentence(name, ab, section.name))
    return 1 if failed else 0


def worlds_of(suite: suites.Suite) -> list[str]:
    """The worlds ``suite``'s cases run on, as they are named (a layout file's by its name)."""
    return list(dict.fromkeys(c.world.partition("#")[0] for s in suite.sections for c in s.cases))


def refuse_other_world(args: argparse.Namespace, suite: suites.Suite) -> None:
    """``--world`` names the world a suite's cases are on, or it is a one-line error: a suite sets
    its cases' worlds (its tasks are the world's), so another world is a suite file's."""
    if getattr(args, "world", None) is None:
        return
    common.world_of(args)  # a world that does not load names its own fault first
    have = worlds_of(suite)
    if have != [str(args.world)]:
        raise InvalidParameterError(
            f"--world {str(args.world)[:100]} does not apply to suite {suite.name!r}: a suite sets the worlds of its "
            f"cases (this one: {', '.join(have)}); to run cases on another world, write a suite file with "
            "world = \"NAME or PATH\" (docs/benchmark.md); valid worlds: " + ", ".join(have))


def probe_learners(plan: benchmark.Plan, robots: benchmark.Robots, seconds: float = 60.0) -> None:
    """Every outside learner of ``plan`` made, learning a few steps and predicting on the first
    case of each of its target robots (``learner_trial.probe``): a learner's fault is one line
    now, before the store is opened; a learner registered in this process only is refused (the
    runs go to worker processes, which cannot see it)."""
    seen: set[tuple[str, str, str]] = set()
    for pair in plan.pairs:
        for name, ms in plan.entries(pair):
            if name in BUILTIN or not ms or (name, pair.case.target, pair.case.world) in seen:
                continue
            seen.add((name, pair.case.target, pair.case.world))
            learner = get(name)
            if learner.origin == RUN_TIME:
                raise PluginError(f"learner {name!r} was registered in this process (register_learner) and a "
                                  "benchmark's runs run in other processes, which cannot see it; install it as a "
                                  "package declaring it under the entry-point group armtransfer.learners "
                                  "(docs/extending.md)")
            target = robots(pair.case.target, pair.case.world)
            learner_trial.probe(learner, target, list(pair.start), list(pair.goal), seconds)


def _run_into(store: ResultStore, plan: benchmark.Plan, robots: dict, args: argparse.Namespace) -> int:
    """Run every run of ``plan`` not in ``store`` yet; a trial run that reads robot 1's path is
    released when its source run is in. Returns how many runs failed."""
    todo, waiting, done = [], {}, 0
    for pair in plan.pairs:
        src = pair.source_run()
        found = store.load_run(src.key())
        if found is None:
            todo.append(src)
            waiting[src.key()] = pair
        runs = plan.all_trial_runs(pair, None if found is None else found["result"])
        left = [r for r in runs if not store.is_done(r.key())]
        todo += left
        done += (found is not None) + len(runs) - len(left)
    to_run = plan.size() - done
    print(f"benchmark {plan.suite.name!r}, seed {plan.seed}: {plan.size()} runs, {done} already done, {to_run} to "
          f"run ({args.executor})")
    if not to_run:
        return 0
    todo.sort(key=lambda r: r.key() not in waiting)  # source runs first: trial runs wait for them
    failed: list[str] = []
    with common.progress_bar(to_run, f"benchmark {plan.suite.name}") as bar:
        def on_done(run: SourceRun, result: dict, secs: float) -> list[TrialRun]:
            store.write_run(run, result, secs)
            bar.update()
            pair = waiting.pop(run.key(), None)
            if pair is None:
                return []
            released = plan.waiting_runs(pair, result)
            more = [r for r in released if not store.is_done(r.key())]
            bar.update(len(released) - len(more))  # a run done before its source's file was set aside
            return more

        def on_failed(run: SourceRun, error: str, attempts: int) -> None:
            store.write_failure(run, error, attempts)
            failed.append(f"{run.key()}: {error.splitlines()[0] if error else error}")
            bar.update(1 + (plan.waiting(waiting[run.key()]) if run.key() in waiting else 0))

        if args.executor == "ray":
            run_ray(todo, robots, args.workers, args.address, on_done, on_failed, retries=args.retries, fn=execute)
        else:
            run_local(todo, robots, args.workers or os.cpu_count() or 1, on_done, on_failed, retries=args.retries,
                      fn=execute)
    if failed:
        print(f"{len(failed)} runs failed; the report is written from the runs that finished")
        for line in failed[:10]:
            print(f"  failed {line}")
    return len(failed)


def write_report(store: ResultStore, plan: benchmark.Plan) -> dict:
    """The report of a store whose runs are all in, written into it (report.md last: it is
    there only when the rest is); returns the statistics. :class:`~armtransfer.experiments.
    benchmark.IncompleteError` when a run is missing."""
    def result(run: SourceRun) -> dict | None:
        rec = store.load_run(run.key())
        return None if rec is None else rec["result"]

    def seconds(run: SourceRun) -> float | None:
        try:
            return float(json.loads((store.timings_dir / f"{run.key()}.json").read_text())["elapsed_seconds"])
        except (OSError, ValueError, KeyError, TypeError):
            return None

    failed = {f["key"]: f["error"] for f in store.failures()}
    records = plan.records(result, failed)
    failures = plan.failures(result, failed)
    summary = benchmark_stats.summarize(records)
    write_report_files(store.root, plan.suite, plan.seed, plan.labels(), list(plan.missing), summary,
                       results_bytes(plan.suite, plan.seed, plan.labels(), list(plan.missing), records, summary,
                                     failures),
                       timings=plan.timings(result, seconds), failures=failures,
                       warnings=benchmark_report.record_warnings(records))
    for line in benchmark_report.record_warnings(records):
        print(f"warning: {line}")
    return summary


def write_report_files(out: Path, suite: suites.Suite, seed: int, ran: list[str], missing: list[str], summary: dict,
                       results: bytes, timings: dict | None = None, failures: list[dict] | None = None,
                       warnings: list[str] | None = None) -> None:
    """A benchmark's report files in ``out``: results.json (``results``, its bytes), timings.json
    when given, the figures, and report.md last, so that it is there only when the rest is."""
    write_bytes_atomic(out / "results.json", results)
    if timings is not None:
        write_json_atomic(out / "timings.json", timings)
    if any(s.name not in summary for s in suite.sections):  # a section whose every record failed: in the
        suite = dataclasses.replace(suite, sections=tuple(s for s in suite.sections if s.name in summary))
    benchmark_report.write_figures(summary, suite, out)
    write_text_atomic(out / "report.md", benchmark_report.report_markdown(suite, seed, summary, ran, missing,
                                                                         failures or [], warnings or []))


def plan_of(store: ResultStore) -> benchmark.Plan:
    """The plan of a benchmark store, made again by this build; a store of a suite this build
    defines otherwise (another version) or does not have is a one-line error."""
    spec = benchmark.Plan.stored_fields(store.meta["spec"]["benchmark"])
    try:
        suite = suite_files.from_dict(spec["suite"], f"{str(store.root)!r}")
    except Exception:  # noqa: BLE001 - any malformed spec is the same one-line refusal
        raise StoreError(f"{str(store.root)!r} holds a benchmark of a suite this build does not have") from None
    seed = spec.get("seed")
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_COUNT:
        raise StoreError(f"{str(store.root)!r} holds the seed {str(seed)[:40]}, which no benchmark takes (--seed is an "
                         f"integer 0..{MAX_COUNT}); it was not written by armtransfer")
    plan = benchmark.plan(suite, seed, ran=spec["methods"], missing=spec["not_in_registry"],
                          preset=spec["preset"], learners=spec["learners"], quality=spec["quality"],
                          run_on=spec["run_on"])
    if content_key(plan.spec()) != store.meta.get("key") or (suite.name in suites.SUITES and not suites.is_builtin(suite)):
        raise StoreError(f"{str(store.root)!r} holds a benchmark of suite {suite.name!r} as another build defined "
                         "it (its version, methods or learner settings differ); rebuild it with that build")
    return plan


def summarize(store: ResultStore) -> int:
    """``armtransfer summarize DIR`` of a benchmark store: its report again, when every run is in."""
    plan = plan_of(store)
    try:
        write_report(store, plan)
    except benchmark.IncompleteError as err:
        named = plan.suite.name if suites.is_builtin(plan.suite) else "FILE (its suite file)"
        raise StoreError(f"{str(store.root)!r}: {err}; finish it with armtransfer benchmark --suite "
                         f"{named} --seed {plan.seed} --out {str(store.root)}") from None
    print(f"wrote {store.root / 'report.md'}")
    return 0

"""The stored specs pinned: what a sweep's, a matrix's and a benchmark's store holds (the spec,
its key, sweep.json's bytes, every run's key) and a benchmark's results.json head, for a fixed
set of inputs, as the build that wrote the stores so far wrote them (tests/spec_pins.json).

A store written by that build must open and resume with nothing to run, so none of these may
change: a spec's defaults are left out of what is stored exactly as before. Written once with
``python tests/test_spec_pins.py --write`` (on the build whose bytes are the reference)."""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

from armtransfer.experiments import benchmark, matrix, suite_files, suites
from armtransfer.experiments import sweep as sweeps
from armtransfer.experiments.store import STORE_FORMAT
from armtransfer.io import parse_toml_bytes

ROOT = Path(__file__).resolve().parents[1]
PINS = Path(__file__).with_name("spec_pins.json")
BASE = Path("/pinned/sweeps")
"""The folder relative arm files are found in (a fixed one, so an arm's path is the same anywhere)."""


def _sha(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def _sweep_pin(spec: dict) -> dict:
    sweep = sweeps.Sweep(spec["name"], spec, tuple(sweeps.expand(spec)))
    meta = {"format": STORE_FORMAT, "name": sweep.name, "key": sweep.key, "spec": sweep.spec}
    return {"key": sweep.key, "spec": json.dumps(spec), "meta": _sha(json.dumps(meta, indent=2, sort_keys=False) + "\n"),
            "runs": len(sweep.runs), "run_keys": _sha("\n".join(run.key() for run in sweep.runs)),
            "run_bytes": _sha("\n".join(json.dumps(run.stored()) for run in sweep.runs))}


SWEEP_VARIANTS = {
    "preset": {"preset": "paper-calibrated"},
    "preset-default": {"preset": "default"},
    "learner-sarsa": {"learner": "sarsa"},
    "learners": {"learner": ["sarsa", "dqn"], "methods": ["none", "dense"], "max_total_steps": 5000},
    "max-total-steps": {"max_total_steps": 4000},
    "world": {"world": "rooms11", "tasks": ["1"]},
    "world-rooms": {"world": "rooms"},
    "start-goal": {"start_goal": [["0,0", "-20,-20"]], "tasks": []},
}


def sweep_pins() -> dict:
    out = {}
    for path in sorted((ROOT / "examples" / "sweeps").glob("*.toml")):
        raw = parse_toml_bytes(path.read_bytes())
        out[path.name] = _sweep_pin(sweeps.normalise(raw, path.name, base=BASE))
    base = {"sweep": {"name": "pin", "tasks": [1], "methods": ["none", "pseudo"], "trials": 2}}
    for name, extra in SWEEP_VARIANTS.items():
        raw = {"sweep": {**base["sweep"], **extra}}
        out[f"variant:{name}"] = _sweep_pin(sweeps.normalise(raw, name, base=BASE))
    return out


MATRIX_VARIANTS: dict[str, dict] = {
    "default": {},
    "preset": {"preset": "paper-calibrated"},
    "world": {"world": "rooms11", "tasks": ["1"]},
    "learners": {"learners": ["sarsa", "dqn"], "methods": ["dense"], "max_total_steps": 3000},
    "max-total-steps": {"max_total_steps": 3000},
    "seeds": {"seeds": [0, 1], "trajectory": "optimal", "name": "m2"},
}


def matrix_pins() -> dict:
    out = {}
    for name, extra in MATRIX_VARIANTS.items():
        args = {"robots": ["coarse", "fine"], "tasks": [1], "methods": ["pseudo", "guided"], "trials": 2, **extra}
        out[name] = _sweep_pin(matrix.matrix_spec(**args))
    return out


PLAN_VARIANTS: dict[str, dict] = {
    "default": {},
    "preset": {"preset": "paper-calibrated"},
    "learners": {"learners": ("sarsa", "dqn")},
    "quality": {"quality": 1.1},
    "quality-int": {"quality": 1},
    "run-on": {"run_on": 2.0},
}


def _plan_pin(plan: benchmark.Plan) -> dict:
    from armtransfer.commands.benchmark import results_bytes

    spec = plan.spec()
    key = sweeps.content_key(spec)
    meta = {"format": STORE_FORMAT, "name": plan.name, "key": key, "spec": spec}
    results = results_bytes(plan.suite, plan.seed, list(plan.methods), list(plan.missing), [], {})
    failed = results_bytes(plan.suite, plan.seed, list(plan.methods), list(plan.missing), [], {},
                           [{"record": "x", "why": "y"}])
    return {"key": key, "spec": json.dumps(spec), "meta": _sha(json.dumps(meta, indent=2, sort_keys=False) + "\n"),
            "results": hashlib.sha256(results).hexdigest(), "results_failed": hashlib.sha256(failed).hexdigest()}


def _made_suite() -> suites.Suite:
    """A suite of every kind of case and section a stored suite may hold (never run)."""
    cases = (suites.Case("coarse", "fine", 1), suites.Case("coarse", "fine", None, wind=0.01, distance=(5, None)),
             suites.Case("coarse", "planar3:joint", 2, state="continuous", noise=0.0),
             suites.Case("coarse", "planar3:joint", 2, state="continuous", noise=0.2, world="rooms11"),
             suites.Case("coarse", "fine", None, start=(0, 0), goal=(-20, -20), cells="even"))
    sections = (suites.Section("a", "every case", cases, 2, 3, 1000),
                suites.Section("b", "own learners and methods", cases[:1], 1, 1, 500, ("sarsa", "dqn"), ("pseudo",)),
                suites.Section("c", "sarsa named", cases[:1], 1, 1, 500, ("sarsa",), ()))
    return suites.Suite("made", 1, False, "made", sections, methods=("none", "pseudo"))


def plan_pins() -> dict:
    out = {}
    ran, missing = benchmark.methods_to_run()
    named = dict(suites.SUITES)
    named["zigzag.toml"] = suite_files.load(ROOT / "examples" / "suites" / "zigzag.toml", suites.SUITES)
    named["made"] = _made_suite()
    for name, suite in named.items():
        for variant, extra in PLAN_VARIANTS.items():
            if variant != "default" and name not in ("fast", "small"):
                continue
            options = {"preset": "default", "learners": None, "quality": benchmark.SOURCE_CONFIG.quality,
                       "run_on": benchmark.SOURCE_CONFIG.run_on, **extra}
            plan = benchmark.Plan(suite, 3, tuple(ran), tuple(missing), (), **options)  # the plan's spec, unrun
            out[f"{name}:{variant}"] = _plan_pin(plan)
    out["fast:planned"] = _plan_pin(benchmark.plan(suites.SUITES["fast"], 0, ran=ran, missing=missing))
    return out


def pins() -> dict:
    return {"sweeps": sweep_pins(), "matrices": matrix_pins(), "plans": plan_pins()}


def test_stored_specs_keep_their_bytes_and_keys():
    pinned = json.loads(PINS.read_text())
    now = pins()
    for kind in pinned:
        assert sorted(now[kind]) == sorted(pinned[kind]), kind
        for name in pinned[kind]:
            assert now[kind][name] == pinned[kind][name], f"{kind} {name}"


if __name__ == "__main__" and sys.argv[1:] == ["--write"]:
    PINS.write_text(json.dumps(pins(), indent=1, sort_keys=True) + "\n")


def test_each_defaults_table_is_what_reading_fills_in():
    """A stored suite is read back through its dataclasses (``suite_files.from_dict``), a plan
    through ``Plan.stored_fields``, a sweep spec through ``spec_fields``: each table's defaults are
    the values reading gives a field left out, and a group is left out only whole."""
    import dataclasses

    from armtransfer.experiments import suite_model
    from armtransfer.experiments.stored_form import fill_in, leave_out

    for kind, table in ((suites.Case, suite_model.CASE_DEFAULTS), (suites.Section, suite_model.SECTION_DEFAULTS),
                        (suites.Suite, suite_model.SUITE_DEFAULTS)):
        fields = {f.name: f.default if f.default is not dataclasses.MISSING else f.default_factory()  # type: ignore[misc]
                  for f in dataclasses.fields(kind)
                  if f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING}
        for names, defaults in table.items():
            names, defaults = ((names,), (defaults,)) if isinstance(names, str) else (names, defaults)
            assert [fields[n] for n in names] == list(defaults), (kind, names)
    case = dataclasses.asdict(suites.Case("coarse", "planar3:joint", 2, state="continuous", noise=0.0))
    assert leave_out(case, suite_model.CASE_DEFAULTS)["noise"] == 0.0  # a continuous case keeps its noise
    assert fill_in(leave_out(case, suite_model.CASE_DEFAULTS), suite_model.CASE_DEFAULTS) == case
    stored = sweeps.normalise({"sweep": {"tasks": [1]}})
    assert set(sweeps.SPEC_DEFAULTS).isdisjoint(stored)
    assert sweeps.spec_fields(stored) == {**stored, **sweeps.SPEC_DEFAULTS}
    assert benchmark.Plan.stored_fields({}) == benchmark.PLAN_DEFAULTS

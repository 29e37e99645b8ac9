"""The learner kernel against its variants, in one process, so that the machine's drift (the
baseline of ``armtransfer bench`` moves by half within an hour here) cancels out.

    python benchmarks/bench_kernels.py                      # plain kernel against the guided one, no guide
    python benchmarks/bench_kernels.py --against 7f3bd4f    # ... and against an older commit's kernel
    python benchmarks/bench_kernels.py --against 7f3bd4f main  # ... and against several
    python benchmarks/bench_kernels.py --fast               # a smoke run
    python benchmarks/bench_kernels.py --method potential breadcrumbs  # methods' shaping, side by side

Each round runs every contender on the same work, in turn: Table I task 1, the fine robot, no
transfer, trials back to back until ``--steps`` steps (``armtransfer bench``'s measurement),
seed = the round. Reported: each contender's median steps/s over the rounds and the median of
the per-round ratios to the first. ``--against REV ...`` loads the learner's kernel (``sarsa.py`` and
its guide) as it was at git revision REV of this checkout, from ``src/armtransfer/learning/`` or, before
the move, ``transfer/``, beside today's (a revision whose kernel takes other arguments than
``sarsa.learn`` gives them fails in one line). ``--method NAME ...`` times the plain kernel with
each method's shaping instead (built once for the fine robot from the coarse robot's shortest path
of task 1, K='auto'): a plugin's method (``docs/extending.md``) beside a built-in one.
"""

from __future__ import annotations

import importlib
import re
import statistics
import subprocess
import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from armtransfer import script
from armtransfer.errors import ArmTransferError
from armtransfer.learning import sarsa
from armtransfer.learning.config import LearnerConfig
from armtransfer.tasks.catalog import table_task
from armtransfer.tasks.grid_robots import grid_robot

ROOT = Path(__file__).resolve().parents[1]


LEARNER_FOLDERS = ("src/armtransfer/learning", "armtransfer/learning", "transfer")
"""Where a revision keeps its learner: today's path, then the one before the move."""
KERNEL_FILES = ("sarsa.py", "guide.py", "guide/")  # a revision's guide is one file or a package
"""The learner's compiled files, loaded as they were at the revision (a folder: all its files);
every other import resolves to today's modules."""
RENAMES = ((re.compile(r"\bfrom tasks\."), "from armtransfer.tasks."),
           (re.compile(r"\bfrom transfer\.rewards import Shaping\b"), "from armtransfer.learning.shaping import Shaping"),
           (re.compile(r"\bfrom transfer\."), "from armtransfer.learning."))
"""Imports of the old tree, in today's names (the kernel's plain run reads only ``Shaping.none``)."""


def _git(*args: str) -> str:
    try:
        proc = subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True, text=True)
    except OSError as e:
        raise ArmTransferError(f"--against needs git and this checkout's history: {e}") from None
    if proc.returncode != 0:
        err = proc.stderr.strip().splitlines()
        raise ArmTransferError(f"git {' '.join(args)} failed: {err[-1] if err else 'no message'}")
    return proc.stdout


def load_revision(rev: str, where: Path):
    """``sarsa`` of git revision ``rev``, with that revision's guide, as package ``rev_<commit>``
    under ``where``. The learner is read from ``src/armtransfer/learning/`` or, for a revision before
    the move, ``transfer/``."""
    tag = "rev_" + _git("rev-parse", "--short=12", f"{rev}^{{commit}}").strip()
    if tag in sys.modules:
        return sys.modules[f"{tag}.sarsa"]
    for folder in LEARNER_FOLDERS:
        names = _git("ls-tree", "-r", "--name-only", rev, "--", folder + "/").split()
        if f"{folder}/sarsa.py" in names:
            break
    else:
        raise ArmTransferError(f"revision {rev!r} has no learner kernel in {' or '.join(LEARNER_FOLDERS)}/")
    own = re.compile(r"\b(?:armtransfer\.learning|transfer)(\.guide\b| import guide\b)")
    pkg = where / tag
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    for name in names:
        rel = name[len(folder) + 1:]
        if not any(rel == k or (k.endswith("/") and rel.startswith(k) and rel.endswith(".py")) for k in KERNEL_FILES):
            continue
        src = own.sub(lambda m: tag + m.group(1), _git("show", f"{rev}:{name}"))
        for pattern, repl in RENAMES:
            src = pattern.sub(repl, src)
        (pkg / rel).parent.mkdir(parents=True, exist_ok=True)
        (pkg / rel).write_text(src)
    sys.path.insert(0, str(where))
    return importlib.import_module(f"{tag}.sarsa")


def measure(learn, steps: int, seed: int) -> float:
    robot = grid_robot("fine")
    start, goal = table_task(1).cells()
    s0 = robot.start_state(start)
    rng = np.random.default_rng(seed)
    done = 0
    t0 = time.perf_counter()
    while done < steps:
        res = learn(robot, s0, goal, LearnerConfig(max_total_steps=steps - done), rng)
        done += int(np.abs(res.episode_steps).sum())
    return done / (time.perf_counter() - t0)


def with_method(name: str):
    """``sarsa.learn`` with method ``name``'s shaping for task 1 (fine robot, the coarse robot's
    shortest path, K='auto'); a method without a reward term of its own is refused."""
    import functools

    from armtransfer.learning import methods, trajectory

    m = methods.get(name)
    if not m.shaped or m.chooses or m.macros:
        raise ArmTransferError(f"--method takes methods whose transfer is a reward term; valid methods: "
                               f"{', '.join(n for n in methods.REWARD_ONLY if not methods.get(n).macros)}")
    start, goal = table_task(1).cells()
    traj = trajectory.shortest(grid_robot("coarse"), start, goal)
    config = LearnerConfig()
    shaping = methods.build_shaping(name, grid_robot("fine"), [traj], "auto", config.step_reward, gamma=config.gamma)
    return functools.partial(sarsa.learn, shaping=shaping)


def guided_kernel_without_guide(*args, **kwargs):
    """``sarsa.learn`` on the kernel compiled with the guide, for a run that has none."""
    plain = sarsa._run_trial
    sarsa._run_trial = sarsa._run_trial_guided
    try:
        return sarsa.learn(*args, **kwargs)
    finally:
        sarsa._run_trial = plain


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    p.add_argument("--rounds", type=int, default=8)
    p.add_argument("--steps", type=int, default=1_000_000, help="steps per contender per round")
    p.add_argument("--against", metavar="REV", nargs="+", default=[],
                   help="also time the kernel of each of these git revisions")
    p.add_argument("--fast", action="store_true", help="a smoke run: 2 rounds of 20,000 steps")
    p.add_argument("--method", metavar="NAME", nargs="+", default=[],
                   help="time the plain kernel with each of these methods' shaping instead (task 1, fine robot)")
    args = p.parse_args(argv)
    return script.run(_run, args)


def _run(args: argparse.Namespace) -> int:
    if args.rounds < 1 or args.steps < 1:
        raise ArmTransferError("--rounds and --steps must be >= 1")
    rounds, steps = (2, 20_000) if args.fast else (args.rounds, args.steps)
    contenders = {"plain kernel (no guide compiled in)": sarsa.learn,
                  "guided kernel, run without a guide": guided_kernel_without_guide}
    if args.method:
        if args.against:
            raise ArmTransferError("--method and --against do not go together")
        contenders = {f"method {name}": with_method(name) for name in args.method}
    with tempfile.TemporaryDirectory() as tmp:
        for rev in args.against:
            contenders[f"kernel at {rev}"] = load_revision(rev, Path(tmp)).learn
        for learn in contenders.values():  # compile or load every kernel outside the timing
            try:
                measure(learn, 1_000, 0)
            except TypeError as e:
                raise ArmTransferError(f"that revision's kernel does not run here: {e}") from None
        rates = {name: [] for name in contenders}
        for r in range(rounds):
            for name, learn in contenders.items():
                rates[name].append(measure(learn, steps, r))
    first = next(iter(rates))
    what = "coarse's shortest path transferred" if args.method else "no transfer"
    print(f"{rounds} rounds of {steps:,} steps each (Table I task 1, fine, {what})")
    for name, xs in rates.items():
        ratio = statistics.median(x / y for x, y in zip(xs, rates[first]))
        print(f"  {name}: median {statistics.median(xs):,.0f} steps/s, "
              f"{ratio:.2f}x the first (per-round ratios {min(x / y for x, y in zip(xs, rates[first])):.2f}-"
              f"{max(x / y for x, y in zip(xs, rates[first])):.2f})")
    return 0


if __name__ == "__main__":
    script.exit_with(main)

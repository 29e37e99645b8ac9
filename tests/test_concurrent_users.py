"""Concurrent users of one cache or store wait for each other or are refused in one line,
never fail half-way: a finished store keeps no lock file, ``summarize`` refuses a store that a
sweep or benchmark is writing, and two processes drawing the same generated arm wait for each
other."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest
from test_sweep_guards import GOOD

from armtransfer.cli import main
from armtransfer.experiments import sweep as sweeps
from armtransfer.experiments.store import LOCK, ResultStore


@pytest.mark.slow
def test_a_finished_store_keeps_no_lock_and_summarize_respects_a_live_one(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text(GOOD)
    out = tmp_path / "store"
    assert main(["sweep", str(path), "--out", str(out)]) == 0
    assert not (out / LOCK).exists()  # finished: nothing left behind
    capsys.readouterr()
    holder = ResultStore.open_for(out, sweeps.load(path))  # a writer holds it (as a running sweep does)
    try:
        before = sorted(p.name for p in out.iterdir())
        assert main(["summarize", str(out)]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"armtransfer summarize: error: store {str(out)!r} is being written by a running "
                              "sweep or benchmark; summarize it when that has finished")
        assert len(err.strip().splitlines()) == 1
        assert sorted(p.name for p in out.iterdir()) == before  # nothing written
    finally:
        holder.unlock()
    assert not (out / LOCK).exists()
    assert main(["summarize", str(out)]) == 0
    assert (out / "summary.md").is_file() and not (out / LOCK).exists()


def test_a_writer_that_starts_while_summarize_reads_is_refused(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(GOOD)
    out = tmp_path / "store"
    ResultStore.open_for(out, sweeps.load(path)).unlock()
    (out / LOCK).touch()  # a store of an older version keeps its (free) lock file
    store = ResultStore.open_existing(out)
    with store.reading():
        proc = subprocess.run([sys.executable, "-m", "armtransfer.cli", "sweep", str(path), "--out", str(out)],
                              capture_output=True, text=True, timeout=120)
        assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
        assert "is in use by another sweep or summarize" in proc.stderr
    ResultStore.open_for(out, sweeps.load(path)).unlock()  # free again


@pytest.mark.slow
def test_two_processes_drawing_one_generated_arm_wait_for_each_other(tmp_path):
    """Both resolve the same arm from an empty cache at once: the second waits for the first's
    draw and reads it; both succeed with the same file."""
    code = ("import sys; from armtransfer.tasks.generated import generated_file\n"
            "xml, side, _ = generated_file('gen:planar:3:11')\n"
            "print(xml, side['seed'])\n")
    env = dict(os.environ, ARMTRANSFER_CACHE=str(tmp_path / "cache"))
    procs = [subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True) for _ in range(2)]
    t0 = time.monotonic()
    outs = [p.communicate(timeout=1200) for p in procs]
    assert all(p.returncode == 0 for p in procs), [o[1][-2000:] for o in outs]
    assert outs[0][0] == outs[1][0] and outs[0][0].strip().endswith(" 11"), outs
    assert time.monotonic() - t0 < 1200

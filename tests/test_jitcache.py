"""Numba's disk cache does not notice an edit to a jitted callee in another file;
``learning.jitcache`` empties the caller's cache when such a file changes."""

import os
import subprocess
import sys
import textwrap

from armtransfer.learning import jitcache, sarsa

CALLER = """
import numba
from . import callee

@numba.njit(cache=True)
def f():
    return callee.g()
"""
GUARD = """
from armtransfer.learning import jitcache
jitcache.invalidate_stale(__name__, [f], [callee.__file__])
"""


def _make(tmp_path, name, guarded):
    pkg = tmp_path / name
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "caller.py").write_text(textwrap.dedent(CALLER) + (textwrap.dedent(GUARD) if guarded else ""))
    (pkg / "callee.py").write_text("import numba\n\n@numba.njit(cache=True)\ndef g():\n    return 1\n")
    return pkg


def _run(tmp_path, name):
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    proc = subprocess.run([sys.executable, "-c", f"import {name}.caller as c; print(c.f())"], cwd=tmp_path,
                          env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return int(proc.stdout.strip())


def _edit_callee(pkg):
    callee = pkg / "callee.py"
    callee.write_text(callee.read_text().replace("return 1", "return 2"))
    st = callee.stat()
    os.utime(callee, (st.st_atime + 10, st.st_mtime + 10))


def test_an_edit_to_a_callee_in_another_file_reaches_the_cached_caller(tmp_path):
    for name, guarded in (("plain_pkg", False), ("guarded_pkg", True)):
        pkg = _make(tmp_path, name, guarded)
        assert _run(tmp_path, name) == 1
        _edit_callee(pkg)
        # Without the guard numba loads the caller compiled against the old callee: the hazard.
        assert _run(tmp_path, name) == (2 if guarded else 1)
    assert _run(tmp_path, "guarded_pkg") == 2  # and the new compile is cached again


def test_the_learner_kernel_guards_its_cache_against_guide_edits():
    stamp = os.path.join(sarsa._run_trial._cache.cache_path, jitcache.STAMP.format(module="sarsa"))
    with open(stamp) as f:  # written at import, for the guide files the kernels call into
        assert f.read() == jitcache.digest(sarsa.DEPENDENCIES)
    assert set(sarsa._guide.FILES) < set(sarsa.DEPENDENCIES)
    assert not jitcache.invalidate_stale("sarsa", [sarsa._run_trial], sarsa.DEPENDENCIES)  # unchanged

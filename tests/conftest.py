import os

# Offscreen rendering needs the GL backend chosen before mujoco is first imported.
os.environ.setdefault("MUJOCO_GL", "egl")

import pytest  # noqa: E402


@pytest.fixture(scope="session")
def reproduce_fast(tmp_path_factory):
    """One fast `armtransfer reproduce --trials 2` shared by the tests that read its output."""
    from armtransfer.cli import main

    out = tmp_path_factory.mktemp("reproduce") / "rep"
    # a lower step cap keeps the controls that never find the goal from dominating the time
    code = main(["reproduce", "--trials", "2", "--max-total-steps", "2000000", "--out", str(out)])
    return code, out

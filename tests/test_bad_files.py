"""Files of every broken kind: one line and exit code 2 from the commands, and a broken run
file in a sweep store is reported and set aside, never fatal."""

import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from armtransfer.cli import main
from armtransfer.io import write_json_atomic
from armtransfer.learning import trajectory as trajectories
from armtransfer.tasks.catalog import table_task
from armtransfer.tasks.grid_robots import grid_robot

BROKEN = {
    "binary": b"\x89PNG\r\n\x1a\n\x00\xff\xfe",
    "deep": b"[" * 200_000 + b"]" * 200_000,
    "not json": b"{nope",
    "empty": b"",
    "a list": b"[1, 2, 3]",
    "wrong shape": json.dumps({"steps": "all of them", "goal": [-8, 12]}).encode(),
    "a string": b'"trajectory"',
}


def _one_line_exit_2(argv, capsys, out=None):
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    if out is not None:
        assert not out.exists()
    return err


@pytest.mark.parametrize("kind", list(BROKEN))
def test_broken_trajectory_files(tmp_path, capsys, kind):
    path = tmp_path / "t.json"
    path.write_bytes(BROKEN[kind])
    err = _one_line_exit_2(["rooms", "--trajectory", str(path), "--trials", "1", "--json", str(tmp_path / "o.json")],
                           capsys, tmp_path / "o.json")
    assert "trajectory file" in err


@pytest.mark.parametrize("kind", list(BROKEN))
def test_broken_mapping_files(tmp_path, capsys, kind):
    path = tmp_path / "m.json"
    path.write_bytes(BROKEN[kind])
    _one_line_exit_2(["rooms", "--method", "mapping", "--mapping", str(path), "--trials", "1"], capsys)


@pytest.mark.parametrize("kind", list(BROKEN))
def test_broken_sweep_store_files(tmp_path, capsys, kind):
    store = tmp_path / "store"
    store.mkdir()
    (store / "sweep.json").write_bytes(BROKEN[kind])
    err = _one_line_exit_2(["summarize", str(store)], capsys)
    assert "sweep.json" in err


def test_a_trajectory_action_the_source_does_not_have_is_refused(tmp_path, capsys):
    coarse = grid_robot("coarse")
    start, goal = table_task(1).cells()
    data = trajectories.shortest(coarse, start, goal).to_json()
    data["steps"][0]["action"] = 10**30
    path = tmp_path / "t.json"
    write_json_atomic(path, data)
    err = _one_line_exit_2(["rooms", "--trajectory", str(path), "--trials", "1"], capsys)
    assert "action index 1000000000000000000000000000000 but the source robot coarse has 4 actions" in err


GOOD_SWEEP = """[sweep]
name = "bad-files"
tasks = [1]
pairs = [["coarse", "fine"]]
methods = ["none"]
seeds = [0, 1]
trials = 1
"""


@pytest.mark.slow
def test_a_broken_run_file_is_set_aside_and_the_run_redone(tmp_path, capsys):
    sweep = tmp_path / "s.toml"
    sweep.write_text(GOOD_SWEEP)
    out = tmp_path / "store"
    assert main(["sweep", str(sweep), "--out", str(out)]) == 0
    runs = sorted((out / "runs").glob("*.json"))
    def content(path):
        return json.loads(path.read_text())

    before = content(runs[0])
    for kind, data in (("binary", BROKEN["binary"]), ("deep", BROKEN["deep"]),
                       ("shape", json.dumps({"key": runs[0].stem, "result": {}}).encode())):
        runs[0].write_bytes(data)
        capsys.readouterr()
        assert main(["sweep", str(sweep), "--out", str(out)]) == 0
        err = capsys.readouterr().err
        assert f"run file '{runs[0]}'" in err and "the run will be redone" in err
        assert content(runs[0]) == before  # redone, the same seed giving the same result
        assert (out / "bad" / runs[0].name).read_bytes() == data
    assert main(["summarize", str(out)]) == 0


@settings(max_examples=25, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.binary(max_size=300) | st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=5),
    lambda children: st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=6), children, max_size=4),
    max_leaves=20).map(lambda v: json.dumps(v).encode()))
def test_any_bytes_as_a_trajectory_file_are_one_line(tmp_path, capsys, data):
    path = tmp_path / "t.json"
    path.write_bytes(data)
    _one_line_exit_2(["rooms", "--trajectory", str(path), "--trials", "1", "--no-controls"], capsys)

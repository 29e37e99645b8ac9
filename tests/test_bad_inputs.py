"""Every command, driven with generated bad input: exit code 2, exactly one line on stderr,
no traceback, and nothing new on disk. (Broken files: tests/test_bad_files.py; sweep files,
the store lock, Ctrl-C, workers and Ray: tests/test_sweep_guards.py.)"""

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from contract import refused

SETTINGS = settings(max_examples=40, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])

text = st.text(alphabet="abcxyz!@#_ .", min_size=1, max_size=6).filter(lambda t: t.strip() and not t.startswith("-"))
nonfinite = st.sampled_from(["nan", "inf", "-inf", "NaN"])


def positive_int_bad():
    return st.one_of(st.integers(max_value=0).map(str), text, nonfinite, st.floats(0.1, 9.9).map(lambda x: f"{x:.2f}"))


def probability_bad():
    return st.one_of(st.floats(1.0001, 1e6).map(repr), st.floats(-1e6, -1e-4).map(repr), text, nonfinite)


def finite_bad():
    return st.one_of(text, nonfinite)


# flag -> bad values, for the flags `rooms` and `arms` share (learning, task, method)
LEARNING = {
    "--trials": positive_int_bad(),
    "--seed": st.one_of(st.integers(max_value=-1).map(str), text, nonfinite),
    "--wind": probability_bad(),
    "--K": st.one_of(st.floats(-1e6, -1e-6).map(repr), text, st.sampled_from(["nan", "-inf"])),
    "--alpha": st.one_of(st.floats(-1e3, 0.0).map(repr), st.floats(1.001, 1e3).map(repr), finite_bad()),
    "--gamma": probability_bad(),
    "--lam": probability_bad(),
    "--epsilon": probability_bad(),
    "--step-reward": finite_bad(),
    "--goal-reward": finite_bad(),
    "--max-episodes": positive_int_bad(),
    "--max-total-steps": positive_int_bad(),
    "--max-episode-steps": positive_int_bad(),
    "--patience": positive_int_bad(),
    "--beta": st.one_of(st.floats(-1e3, -1e-6).map(repr), finite_bad()),
    "--max-span": positive_int_bad(),
    "--task": st.one_of(st.integers(min_value=5, max_value=10**6).map(str), st.integers(max_value=0).map(str),
                        text),
    "--method": text.map(lambda t: "m" + t),
}

cells = st.one_of(
    st.tuples(st.integers(-200, 200), st.integers(-200, 200)).filter(lambda c: max(abs(c[0]), abs(c[1])) > 25),
    st.sampled_from([(-3, 0), (-3, 7), (5, -7), (-20, 3)]),  # wall cells
).map(lambda c: f"{c[0]},{c[1]}")
malformed = st.one_of(text, st.sampled_from(["1", "1,2,3", "1.5,2", ",", "x,y"]))


@SETTINGS
@given(data=st.data())
def test_rooms_bad_numbers(tmp_path, monkeypatch, capsys, data):
    flag = data.draw(st.sampled_from(sorted(LEARNING)))
    value = data.draw(LEARNING[flag])
    refused(["rooms", f"{flag}={value}", "--json", "out.json"], tmp_path, monkeypatch, capsys)


@SETTINGS
@given(data=st.data())
def test_arms_bad_numbers(tmp_path, monkeypatch, capsys, data):
    flag = data.draw(st.sampled_from(sorted(LEARNING)))
    value = data.draw(LEARNING[flag])
    refused(["arms", "--fast", f"{flag}={value}", "--out", "run"], tmp_path, monkeypatch, capsys)


@SETTINGS
@given(start=st.one_of(cells, malformed), goal=st.sampled_from(["-8,12", "0,0"]), which=st.booleans())
def test_bad_cells(tmp_path, monkeypatch, capsys, start, goal, which):
    a, b = (start, goal) if which else (goal, start)
    refused(["rooms", f"--start={a}", f"--goal={b}", "--json", "o.json"], tmp_path, monkeypatch, capsys)


@SETTINGS
@given(value=st.one_of(st.floats(-10, 0).map(repr), nonfinite, text))
def test_arms_bad_cell_size_and_base(tmp_path, monkeypatch, capsys, value):
    refused(["arms", "--fast", f"--cell-size={value}", "--out", "run"], tmp_path, monkeypatch, capsys)
    refused(["arms", "list", "--arm", "planar2", f"--cell-size={value}"], tmp_path, monkeypatch, capsys)


@SETTINGS
@given(value=st.one_of(nonfinite.map(lambda v: f"{v},0,0"), malformed))
def test_bad_base_pos(tmp_path, monkeypatch, capsys, scara_xml, value):
    refused(["arms", "list", "--arm-xml", str(scara_xml), "--tip-site", "pen_tip", f"--base-pos={value}"],
              tmp_path, monkeypatch, capsys)


@SETTINGS
@given(flag=st.sampled_from(["--trials", "--seeds"]), value=st.one_of(st.integers(max_value=-1).map(str), text))
def test_matrix_bad_numbers(tmp_path, monkeypatch, capsys, flag, value):
    refused(["matrix", "--robots", "coarse,fine", f"{flag}={value}", "--out", "m"], tmp_path, monkeypatch, capsys)


@SETTINGS
@given(flag=st.sampled_from(["--trials", "--seed", "--max-total-steps"]),
       value=st.one_of(st.integers(max_value=-1).map(str), text, nonfinite))
def test_reproduce_bad_numbers(tmp_path, monkeypatch, capsys, flag, value):
    refused(["reproduce", f"{flag}={value}", "--out", "rep"], tmp_path, monkeypatch, capsys)


@SETTINGS
@given(flag=st.sampled_from(["--steps", "--repeats", "--seed", "--baseline-steps", "--baseline-repeats"]),
       value=st.one_of(st.integers(max_value=-1).map(str), text))
def test_bench_bad_numbers(tmp_path, monkeypatch, capsys, flag, value):
    refused(["bench", f"{flag}={value}", "--json", "b.json"], tmp_path, monkeypatch, capsys)


@SETTINGS
@given(flag=st.sampled_from(["--workers", "--retries", "--max-runs"]),
       value=st.one_of(st.integers(max_value=-1).map(str), text))
def test_sweep_bad_numbers(tmp_path, monkeypatch, capsys, flag, value):
    (tmp_path / "s.toml").write_text('[sweep]\ntasks = [1]\n')
    refused(["sweep", "s.toml", f"{flag}={value}", "--out", "store"], tmp_path, monkeypatch, capsys)
    (tmp_path / "s.toml").unlink()


@pytest.mark.parametrize("argv", [
    ["rooms", "--json", "/proc/x.json"],
    ["rooms", "--json", "."],
    ["arms", "--fast", "--out", "/proc/x"],
    ["arms", "--fast", "--render", "/proc/x.mp4", "--out", "run"],
    ["arms", "--fast", "--render", "video.avi", "--out", "run"],
    ["arms", "--fast", "--json", "/proc/r.json", "--out", "run"],
    ["reproduce", "--out", "/proc/rep"],
    ["bench", "--json", "/proc/b.json"],
    ["matrix", "--robots", "coarse,fine", "--out", "/proc/m"],
    ["summarize", "nowhere"],
])
def test_bad_outputs(tmp_path, monkeypatch, capsys, argv):
    refused(argv, tmp_path, monkeypatch, capsys)


def test_a_non_empty_out_is_refused(tmp_path, monkeypatch, capsys):
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "keep.txt").write_text("mine")
    for argv in (["arms", "--fast", "--out", "run"], ["reproduce", "--out", "run"]):
        refused(argv, tmp_path, monkeypatch, capsys)
    assert (tmp_path / "run" / "keep.txt").read_text() == "mine"

"""The first hour in a notebook and a shell: short reprs, tidy frames, --version,
python -m armtransfer, a help that says what each command is for, headers that say what
the cells hold."""

import importlib.metadata
import shlex
import subprocess
import sys

import pytest

import armtransfer
from armtransfer.cli import COMMANDS, build_parser, main
from armtransfer.experiments import tables

pd = pytest.importorskip("pandas")  # the 'frames' extra, in the 'test' extra too


@pytest.fixture(scope="module")
def ten_trials():
    """A 10-trial result with its controls; a lower step cap keeps the controls quick."""
    return armtransfer.transfer("coarse", "fine", task=1, methods=["none", "pseudo", "dense"], trials=10, seed=1,
                                max_total_steps=300_000)


def test_the_repr_of_a_10_trial_result_is_short_and_names_the_methods_and_means(ten_trials):
    text = repr(ten_trials)
    assert len(text) < 1500, len(text)
    assert "array(" not in text and "next_state" not in text
    assert text.startswith("<TransferResult task 1: (0, 0) -> (-8, 12), coarse -> fine")
    summary = ten_trials.to_json()
    for label, entry in [*summary["results"].items(),
                         *((f"{m} [{k}]", e) for k, by in summary["controls"].items() for m, e in by.items())]:
        line = next(line for line in text.splitlines() if line.strip().startswith(label + " "))
        assert tables.fmt_mean(entry) in line, (label, line)


def test_a_method_result_is_one_line(ten_trials):
    text = repr(ten_trials.methods["pseudo"])
    assert "\n" not in text and "array(" not in text
    assert text.startswith("<MethodResult pseudo: 10 trials, reached ")


def test_jupyter_shows_the_table_the_command_prints(capsys):
    assert main(["rooms", "--task", "1", "--trials", "3", "--seed", "2", "--method", "none", "pseudo",
                 "--no-controls"]) == 0
    printed = capsys.readouterr().out
    result = armtransfer.transfer("coarse", "fine", task=1, methods=["none", "pseudo"], trials=3, seed=2,
                                  controls=False)
    shown = result._repr_markdown_()
    table = tables.transfer_table(result.to_json())
    assert table in shown and table in printed
    assert tables.transfer_heading(result.to_json()) in shown


def test_a_3_trial_table_heads_its_median_column_with_the_coverage_it_holds(ten_trials):
    three = armtransfer.transfer("coarse", "fine", task=1, methods=["none", "pseudo"], trials=3, seed=2,
                                 controls=False)
    table = tables.transfer_table(three.to_json())
    header = table.splitlines()[0]
    assert "median [75% CI]" in header and "95% CI]" not in header.split("median")[1].split("|")[0]
    assert "(75% CI)" not in table
    assert "median [95% CI]" in tables.transfer_table(ten_trials.to_json()).splitlines()[0]


def test_rows_of_different_coverage_name_it_in_each_cell():
    entry = {"exploration_steps": [1, 2, 3], "mean": 2.0, "ci95": [1.0, 3.0], "median": 2.0,
             "median_ci95": [1.0, 3.0], "converged": [True] * 3}
    table = tables.method_table({"a": dict(entry, median_ci_coverage=0.75),
                                 "b": dict(entry, median_ci_coverage=0.98)})
    assert "median [CI, coverage named when below 95%]" in table and "(75% CI)" in table


def test_to_frame_has_one_row_per_trial_of_every_method_and_control(ten_trials):
    df = ten_trials.to_frame()
    runs = ten_trials.runs()
    assert len(runs) == 3 + 2 * 2  # none, pseudo, dense, and the two shaped methods under both controls
    assert len(df) == 10 * len(runs)
    for run in runs:
        rows = df[(df.method == run.method) & (df.control == (run.control or "none"))]
        assert list(rows.trial) == list(range(10))
        steps = [None if pd.isna(x) else int(x) for x in rows.exploration_steps]
        assert steps == run.column("exploration_steps")
        assert list(rows.reached) == [x is not None for x in steps]
        assert list(rows.total_steps.astype(object).where(rows.total_steps.notna(), None)) == run.column("total_steps")
        assert list(rows.converged) == run.column("converged")
    for column in ("greedy_steps", "episodes", "jumpstart", "area", "transfer_ratio", "step_cap", "K_used",
                   "task", "start_x", "goal_y", "source", "target", "seed", "wind", "epsilon", "alpha",
                   "max_total_steps", "trajectory_length"):
        assert column in df.columns, column
    assert set(df.source) == {"coarse"} and set(df.max_total_steps) == {300_000}
    assert (df.step_cap == 300_000).all()


def test_a_default_groupby_keeps_the_main_runs(ten_trials):
    """The runs on the given trajectory are labelled, not NaN, so pandas' default groupby (which
    drops missing keys) still counts them beside the controls."""
    df = ten_trials.to_frame()
    assert df.control.notna().all()
    assert set(df.control) == {"none", "shuffled", "random"}
    counts = df.groupby(["method", "control"]).size()
    assert counts.sum() == len(df)
    for method in ("none", "pseudo", "dense"):
        assert counts[(method, "none")] == 10
    assert counts[("pseudo", "shuffled")] == 10 and ("none", "shuffled") not in counts.index


def test_to_frame_without_pandas_names_the_extra(ten_trials, monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(armtransfer.ArmTransferError) as err:
        ten_trials.to_frame()
    assert str(err.value) == "to_frame() needs pandas: pip install 'armtransfer[frames]'"


def test_a_matrix_store_leaves_as_a_frame_and_names_what_is_missing(tmp_path):
    from armtransfer.experiments.store import ResultStore

    out = tmp_path / "m"
    assert main(["matrix", "--robots", "coarse,fine", "--tasks", "1", "--methods", "none", "pseudo",
                 "--trials", "2", "--out", str(out)]) == 0
    store = ResultStore.open_existing(out)
    records = store.records()
    assert len(records) == 4 * 2  # every ordered pair, a robot to itself too, x two methods
    df = store.to_frame()
    assert len(df) == 2 * len(records)
    for rec in records:
        rows = df[df.run == rec["config"]["key"]]
        assert list(rows.trial) == [0, 1] and set(rows.method) == {rec["config"]["method"]}
        assert [None if pd.isna(x) else int(x) for x in rows.exploration_steps] == rec["result"]["exploration_steps"]
    for column in ("source", "target", "task", "start_x", "seed", "epsilon", "K", "K_used", "step_cap", "reached"):
        assert column in df.columns, column
    assert df.attrs == {"runs": 8, "failed": [], "missing": []}
    gone = records[0]["config"]["key"]
    store.run_path(gone).unlink()
    assert store.to_frame().attrs["missing"] == [gone]


def test_version_prints_the_installed_version(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["--version"])
    assert exit_.value.code == 0
    assert capsys.readouterr().out == f"armtransfer {importlib.metadata.version('armtransfer')}\n"
    assert armtransfer.__version__ == importlib.metadata.version("armtransfer")


def test_python_m_armtransfer_help(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "armtransfer", "--help"], capture_output=True, text=True,
                          timeout=300, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("usage: armtransfer [-h] [--version] COMMAND ...")
    for name in COMMANDS:
        assert f"\n  {name} " in proc.stdout and f"e.g. armtransfer {name}" in proc.stdout, name
    assert "``" not in proc.stdout and "subcommand per module" not in proc.stdout


def test_each_command_says_what_it_is_for_in_one_voice_with_an_example_that_parses():
    import importlib

    parser = build_parser()
    for name, module_name in COMMANDS.items():
        module = importlib.import_module(f"armtransfer.commands.{module_name}")
        assert module.HELP[0].isupper() and module.HELP.endswith("."), name
        assert "``" not in module.HELP and "\n" not in module.HELP
        words = shlex.split(module.EXAMPLE)
        assert words[:2] == ["armtransfer", name]
        assert parser.parse_args(words[1:]).command == name

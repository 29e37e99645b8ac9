"""`armtransfer summarize RESULTS --out DIR`: a benchmark's results file, as docs/ keeps it,
made into its report again; every number recomputed from the records and checked against
the file's own bytes."""

from __future__ import annotations

import gzip
import json
from pathlib import Path

import pytest

from armtransfer.cli import main

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def results(benchmark_fast):
    codes, root = benchmark_fast
    assert codes == [0, 0]
    return root / "one"


@pytest.mark.parametrize("packed", [False, True], ids=["json", "gzip"])
def test_a_results_file_gives_its_report_again_byte_for_byte(results, tmp_path, packed, capsys):
    src = tmp_path / ("results.json.gz" if packed else "results.json")
    data = (results / "results.json").read_bytes()
    src.write_bytes(gzip.compress(data) if packed else data)
    out = tmp_path / "again"
    assert main(["summarize", str(src), "--out", str(out)]) == 0
    assert "the same bytes" in capsys.readouterr().out
    for name in ("report.md", "results.json", "survival_fast.png", "learning_curves_fast.png"):
        assert (out / name).read_bytes() == (results / name).read_bytes(), name


def _refused(argv, capsys) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err


def test_an_edited_record_is_caught_and_nothing_is_written(results, tmp_path, capsys):
    data = json.loads((results / "results.json").read_text())
    data["records"][0]["first_exposure"][0] += 1
    src = tmp_path / "results.json"
    src.write_text(json.dumps(data, indent=1) + "\n")
    err = _refused(["summarize", str(src), "--out", str(tmp_path / "again")], capsys)
    assert "differ from the file's" in err
    assert not (tmp_path / "again").exists()


def test_another_version_of_the_suite_is_named(results, tmp_path, capsys):
    data = json.loads((results / "results.json").read_text())
    data["suite"]["version"] += 7
    src = tmp_path / "results.json"
    src.write_text(json.dumps(data))
    err = _refused(["summarize", str(src), "--out", str(tmp_path / "again")], capsys)
    assert f"version {data['suite']['version']}" in err and "this build has version" in err


@pytest.mark.parametrize("content, words", [
    (b"\x1f\x8b not really", "not valid gzip"),
    (b"[1, 2]", "not a benchmark's results file"),
    (b'{"records": [], "suite": {}, "seed": "0"}', "field 'seed' must be a int"),
])
def test_bad_results_files_are_one_line(tmp_path, capsys, content, words):
    src = tmp_path / ("r.json.gz" if content.startswith(b"\x1f") else "r.json")
    src.write_bytes(content)
    assert words in _refused(["summarize", str(src), "--out", str(tmp_path / "o")], capsys)
    assert not (tmp_path / "o").exists()


def test_a_results_file_needs_an_out_directory(results, capsys):
    assert "needs --out" in _refused(["summarize", str(results / "results.json")], capsys)


KEPT = ROOT / "docs" / "benchmark-standard" / "results.json.gz"


def test_an_absent_results_file_is_named_as_absent(tmp_path, capsys):
    err = _refused(["summarize", str(tmp_path / "results.json.gz"), "--out", str(tmp_path / "o")], capsys)
    assert "does not exist" in err and "results.json.gz" in err
    assert not (tmp_path / "o").exists()


@pytest.mark.slow
@pytest.mark.skipif(not KEPT.exists(), reason="no standard report kept in docs/")
def test_the_kept_standard_report_comes_back_from_its_records(tmp_path, capsys):
    out = tmp_path / "again"
    assert main(["summarize", str(KEPT), "--out", str(out)]) == 0
    assert (out / "report.md").read_text() == (KEPT.parent / "report.md").read_text()


def test_the_readme_shows_the_tables_of_the_kept_report():
    """docs/benchmark.md's standard-suite tables are research/readme_table.py's output on the kept results file,
    character for character: no number in them is typed by hand."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("readme_table", ROOT / "research" / "readme_table.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    page = (ROOT / "docs" / "benchmark.md").read_text()
    shown = page.split("<!-- benchmark-tables -->\n", 1)[1].split("<!-- /benchmark-tables -->", 1)[0]
    assert shown == module.tables(module.pooled(KEPT))


SMALL = ROOT / "docs" / "benchmark-small" / "results.json.gz"


def _readme_table_module():
    import importlib.util

    spec = importlib.util.spec_from_file_location("readme_table", ROOT / "research" / "readme_table.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_readme_shows_the_learner_table_of_the_kept_small_report():
    """README's learner table (SARSA, DQN, PPO each against its own ``none``) is
    research/readme_table.py --learners on the kept small-suite results, character for character."""
    module = _readme_table_module()
    page = (ROOT / "docs" / "benchmark.md").read_text()
    shown = page.split("<!-- learner-table -->\n", 1)[1].split("<!-- /learner-table -->", 1)[0]
    assert shown == module.learner_table(module.pooled(SMALL))
    assert [r.split(" | ")[0] for r in shown.splitlines()[2:]] == ["| sarsa", "| dqn", "| ppo"]


def test_the_learner_table_puts_each_learner_against_its_own_none():
    import importlib.util

    spec = importlib.util.spec_from_file_location("readme_table", ROOT / "research" / "readme_table.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)

    def ab(f):
        return {"factor": f, "ci95": [f / 2, f * 2], "worst": f / 3, "seeds": 10, "p_holm": 0.5, "verdicts": 4,
                "detectable": [0.5, 2.0]}

    pooled = {"small": {"pseudo": {"none": {"convergence": ab(1.5), "first_exposure": ab(2.0)}},
                        "pseudo@dqn": {"none@dqn": {"convergence": ab(3.0), "first_exposure": ab(4.0)}},
                        "dense@dqn": {"none@dqn": {"convergence": ab(5.0)}},
                        "pseudo@ppo": {"none@ppo": {"first_exposure": ab(6.0)}}}}
    rows = module.learner_table(pooled).splitlines()
    assert [r.split(" | ")[0] for r in rows[2:]] == ["| sarsa", "| dqn", "| ppo"]
    # columns: good path (pseudo, dense), settled clock (pseudo, dense), first exposure (pseudo, dense)
    assert rows[3].split(" | ")[1] == "not measured" and rows[3].split(" | ")[2] == "not measured"
    assert rows[3].split(" | ")[3].startswith("3×") and rows[3].split(" | ")[4].startswith("5×")
    assert rows[4].split(" | ")[1] == "not measured" and rows[4].split(" | ")[3] == "n/a"
    assert rows[4].split(" | ")[5].startswith("6×")
    assert "n.s." in rows[2]


PAPER = ROOT / "docs" / "benchmark-paper" / "results.json.gz"


def test_the_paper_suites_good_path_tables_are_those_of_its_kept_report():
    """docs/benchmark.md's paper-suite tables (the good-path clock first) are research/readme_table.py's
    output on the kept paper-suite results, character for character; the control lazy is among them."""
    module = _readme_table_module()
    page = (ROOT / "docs" / "benchmark.md").read_text()
    shown = page.split("<!-- paper-clock-tables -->\n", 1)[1].split("<!-- /paper-clock-tables -->", 1)[0]
    assert shown == module.tables(module.pooled(PAPER), settled=False)
    assert shown.startswith("**Good path") and "`lazy` vs `plan`" in shown.splitlines()[2]


def test_the_readme_headline_is_the_compact_table_of_the_kept_standard_report():
    """README's one headline table is research/readme_table.py --compact on the kept standard results:
    a row per comparison (the control lazy last), a column per section, the good-path clock with
    the settled quality beside it."""
    module = _readme_table_module()
    readme = (ROOT / "README.md").read_text()
    shown = readme.split("<!-- headline-table -->\n", 1)[1].split("<!-- /headline-table -->", 1)[0]
    assert shown == module.compact(module.pooled(KEPT))
    rows = shown.splitlines()
    assert rows[-1].startswith("| `lazy` vs `plan` |") and len(rows) == 2 + len(module.COLUMNS)
    assert "not measured" not in shown  # the kept standard run has the good-path clock


def test_a_compact_cell_carries_the_factor_its_interval_the_worst_pair_and_the_settled_quality():
    module = _readme_table_module()
    block = {"good_path": {"factor": 3.0, "ci95": [1.5, 6.0], "worst": 0.5, "seeds": 10, "p_holm": 0.001,
                           "verdicts": 4, "detectable": [0.5, 2.0], "bounds": 2},
             "settled": {"method": {"median": 1.0, "worst": 1.2}, "baseline": {"median": 1.05, "worst": 1.4}}}
    text = module.compact_cell(block)
    assert text.startswith("3× [1.5, 6×] ") and "worst 0.5×, 2 pairs capped" in text
    assert text.endswith("; 1.00/1.20 vs 1.05/1.40")
    assert module.compact_cell(None) == "n/a" and module.compact_cell({"good_path": None}) == "not measured"


def test_the_results_page_shows_the_calibrated_seeds_table():
    """docs/results.md's paper-calibrated table (Tables II and V beside ours, which the README's claim
    cites) is research/calibrated_seeds.py's summary of the kept studies."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("calibrated_seeds", ROOT / "research" / "calibrated_seeds.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    kept = ROOT / "docs" / "reproduce-calibrated" / "seeds"
    studies = {int(p.name.split("-")[1].split(".")[0]): module.load(p) for p in sorted(kept.glob("study-*.json.gz"))}
    assert len(studies) >= 3
    page = (ROOT / "docs" / "results.md").read_text()
    shown = page.split("<!-- calibrated-seeds -->\n", 1)[1].split("<!-- /calibrated-seeds -->", 1)[0]
    assert shown == module.table(studies) and (kept / "seeds.md").read_text() == module.summary(studies)

"""No output is lost after the work is done: outputs on one path, an output inside the
output directory, a symlinked --out and two runs into one --out are all settled before any
work, in one line."""

import os

import pytest

from armtransfer.cli import main
from contract import refused
from armtransfer.errors import OutputError
from armtransfer.io import check_distinct_outputs, staged_directory

FAST_ARMS = ["arms", "--fast", "--no-video", "--source", "coarse", "--target", "fine", "--trajectory", "optimal",
             "--trials", "1"]


@pytest.mark.parametrize("extra,message", [
    (["--json", "D/extra.json"], "--json"),
    (["--json", "./D/sub/../extra.json"], "--json"),
    (["--render", "D/v.mp4"], "--render"),
    (["--method", "mapping", "--mapping", "D/map.json"], "--mapping"),
])
def test_an_output_inside_the_output_directory_isrefused(extra, message, tmp_path, monkeypatch, capsys):
    err = refused([*FAST_ARMS, "--out", "D", *extra], tmp_path, monkeypatch, capsys)
    assert f"{message} " in err and "inside the output directory --out" in err


def test_two_outputs_on_one_path_arerefused(tmp_path, monkeypatch, capsys):
    err = refused(["rooms", "--method", "mapping", "--mapping", "F", "--json", "./F", "--trials", "1"], tmp_path,
                   monkeypatch, capsys)
    assert "--json and --mapping name the same path" in err
    (tmp_path / "real.json").write_text("{}")
    os.symlink("real.json", tmp_path / "alias.json")
    with pytest.raises(OutputError, match="same path"):
        check_distinct_outputs({"--json": tmp_path / "real.json", "--mapping": tmp_path / "alias.json"})


def test_a_symlinked_out_to_an_empty_folder_is_written_through(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "target").mkdir()
    os.symlink("target", tmp_path / "link")
    assert main([*FAST_ARMS, "--out", "link"]) == 0
    assert (tmp_path / "link").is_symlink()
    assert (tmp_path / "target" / "results.json").is_file()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")], "a staging folder was left"


def test_a_second_run_into_the_same_out_is_refused_before_its_work(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    from armtransfer.experiments import engines

    def boom(*a, **k):
        raise AssertionError("the second run started learning")

    with staged_directory(tmp_path / "D") as tmp:  # the first run, still working
        (tmp / "partial.json").write_text("{}")
        monkeypatch.setattr(engines.Tabular, "trials", boom)
        assert main([*FAST_ARMS, "--out", "D"]) == 2
        err = capsys.readouterr().err
        assert "another run is writing into" in err and len(err.strip().splitlines()) == 1
        monkeypatch.undo()
    assert sorted(p.name for p in (tmp_path / "D").iterdir()) == ["partial.json"]  # the first run's, whole
    assert [p.name for p in tmp_path.iterdir()] == ["D"]


def test_a_finished_out_is_not_written_again(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main([*FAST_ARMS, "--out", "D"]) == 0
    capsys.readouterr()
    err = refused([*FAST_ARMS, "--out", "D"], tmp_path, monkeypatch, capsys)
    assert "exists and is not empty" in err


def test_the_same_sweep_writes_the_same_run_files(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text('[sweep]\nname = "d"\ntasks = [1]\npairs = [["coarse", "fine"]]\n'
                                     'methods = ["none", "pseudo"]\nseeds = [0, 1]\ntrials = 1\n'
                                     'trajectory = "optimal"\nmax_episodes = 30\n')
    stores = []
    for name in ("a", "b"):
        assert main(["sweep", "s.toml", "--out", name, "--workers", "1"]) == 0
        stores.append({p.relative_to(tmp_path / name): p.read_bytes()
                       for p in (tmp_path / name).rglob("*") if p.is_file() and p.name != ".lock"})
    runs = [{k: v for k, v in s.items() if k.parts[0] != "timings"} for s in stores]
    assert runs[0] == runs[1] and len([k for k in runs[0] if k.parts[0] == "runs"]) == 4
    timings = sorted(k for k in stores[0] if k.parts[0] == "timings")
    assert [t.name for t in timings] == sorted(k.name for k in runs[0] if k.parts[0] == "runs")
    assert b"elapsed_seconds" not in b"".join(runs[0].values())

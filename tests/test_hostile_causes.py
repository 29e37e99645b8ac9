"""The nine causes of the second hostile audit, each closed as a class at its shared mechanism
and tested over its members: environment variables (checked by the command before it runs),
input files (``io.read_input``/``io.check_input``), OS errors on paths (``io.path_error`` and the
command's catch), the store's own files (checked on read), stdout (``script.exit_with``), a
refusal before the work (the store's open), arm names (``tasks.arms.check_arm_name``) and the
remaining API gaps. ``dev/audit.py`` has the same causes as command-line cases."""

from __future__ import annotations

import errno
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from armtransfer.cli import main
from armtransfer.errors import ArmModelError, ArmTransferError, InvalidParameterError

SWEEP = """[sweep]
name = "causes"
tasks = [1]
pairs = [["coarse", "fine"]]
methods = ["none"]
seeds = [0]
trials = 1
trajectory = "optimal"
max_episodes = 30
"""


def one_line(capsys, *words: str) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for word in words:
        assert word in err, err
    return err


# ---- 1. environment variables ----------------------------------------------------------

@pytest.mark.parametrize("name,value,words", [
    ("ARMTRANSFER_CPUS", "0", ["ARMTRANSFER_CPUS", "1..4,096"]),
    ("ARMTRANSFER_CPUS", "abc", ["ARMTRANSFER_CPUS", "'abc'"]),
    ("ARMTRANSFER_CPUS", "-3", ["ARMTRANSFER_CPUS"]),
    ("ARMTRANSFER_CPUS", "1000000000", ["ARMTRANSFER_CPUS"]),
    ("ARMTRANSFER_CACHE", "{file}/cache", ["ARMTRANSFER_CACHE", "Not a directory"]),
    ("ARMTRANSFER_CACHE", "{file}", ["ARMTRANSFER_CACHE", "is not a folder"]),
    ("ARMTRANSFER_CACHE", "x" * 300, ["ARMTRANSFER_CACHE", "File name too long"]),
])
def test_an_environment_variable_is_checked_before_anything_is_written(tmp_path, monkeypatch, capsys, name, value,
                                                                      words):
    (tmp_path / "s.toml").write_text(SWEEP)
    (tmp_path / "f").write_text("a file\n")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(name, value.format(file=tmp_path / "f"))
    assert main(["sweep", "s.toml", "--out", "store"]) == 2
    one_line(capsys, *words)
    assert not (tmp_path / "store").exists()


def test_xdg_cache_home_is_checked_only_without_armtransfer_cache(tmp_path, monkeypatch):
    from armtransfer.environment import check_environment

    (tmp_path / "f").write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "f"))
    check_environment()  # ARMTRANSFER_CACHE (the tests' cache) is used, not XDG_CACHE_HOME
    monkeypatch.delenv("ARMTRANSFER_CACHE")
    with pytest.raises(InvalidParameterError, match="XDG_CACHE_HOME"):
        check_environment()


# ---- 2. input files: regular, bounded --------------------------------------------------

def _trajectory(path):
    from armtransfer.learning.trajectory import load

    load(path)


def _mapping(path):
    from armtransfer.learning.mapping import ActionMapping

    ActionMapping.load(path)


def _sweep(path):
    from armtransfer.experiments.sweep import load

    load(path)


def _arm(path):
    from armtransfer.tasks.arms import arm_robot

    arm_robot(None, "joint", xml_path=path, tip_site="pen_tip")


def _included(path):
    """An arm file that <include>s ``path``."""
    from armtransfer.ik.scene import model_files

    main_file = Path(path).parent / "main.xml"
    main_file.write_text(f'<mujoco><include file="{Path(path).name}"/></mujoco>')
    model_files(main_file)


READERS = {"trajectory": _trajectory, "mapping": _mapping, "sweep": _sweep, "arm": _arm, "arm include": _included}


def _make(kind: str, path: Path) -> Path:
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "directory":
        path.mkdir()
    elif kind == "oversize":  # sparse: 17 MiB without writing them
        with open(path, "wb") as fh:
            fh.truncate(17 * 2**20)
    elif kind == "device":
        return Path("/dev/zero")
    return path


@pytest.mark.parametrize("kind,words", [("fifo", "a FIFO"), ("directory", "a directory"), ("device", "character device"),
                                        ("oversize", "over the bound of 16,777,216 bytes")])
@pytest.mark.parametrize("reader", list(READERS))
def test_an_input_file_is_read_only_when_regular_and_bounded(tmp_path, reader, kind, words):
    import time

    path = _make(kind, tmp_path / "input.xml")
    t0 = time.monotonic()
    with pytest.raises(ArmTransferError) as err:
        READERS[reader](path)
    assert time.monotonic() - t0 < 10
    assert words in str(err.value) and str(path) in str(err.value) and "\n" not in str(err.value)


# ---- 3. OS errors on paths -------------------------------------------------------------

@pytest.mark.parametrize("code", ["ENAMETOOLONG", "ENOSPC", "EROFS", "EACCES", "ENOTDIR", "EDQUOT"])
def test_an_os_error_on_a_path_is_one_line_naming_the_path(monkeypatch, capsys, code):
    """Whatever a command was doing: the file system's refusal of a path is one line."""
    from armtransfer.commands import rooms

    number = getattr(errno, code)

    def refused(args):
        raise OSError(number, os.strerror(number), "runs/" + "y" * 300 + "/results.json")

    monkeypatch.setattr(rooms, "run", refused)
    assert main(["rooms", "--trials", "1"]) == 2
    err = one_line(capsys, os.strerror(number), "runs/yyy", "(318 characters)")
    assert err.startswith("armtransfer rooms: error: cannot use ")


def test_a_disk_error_without_a_path_is_one_line_and_a_bug_keeps_its_traceback(monkeypatch, capsys):
    from armtransfer.commands import rooms

    monkeypatch.setattr(rooms, "run", lambda args: (_ for _ in ()).throw(OSError(errno.ENOSPC, "No space left")))
    assert main(["rooms", "--trials", "1"]) == 2
    one_line(capsys, "No space left")
    monkeypatch.setattr(rooms, "run", lambda args: (_ for _ in ()).throw(OSError(errno.EINVAL, "a bug")))
    with pytest.raises(OSError):
        main(["rooms", "--trials", "1"])


@pytest.mark.parametrize("argv", [
    ["rooms", "--trials", "1", "--json", "{long}.json"], ["sweep", "s.toml", "--out", "{long}"], ["summarize", "{long}"],
    ["arms", "--fast", "--no-video", "--source", "coarse", "--target", "fine", "--out", "{long}"],
    ["arms", "generate", "--family", "planar", "--dof", "2", "--out", "{long}"], ["bench", "--json", "{long}.json"],
    ["matrix", "--robots", "coarse,fine", "--methods", "none", "pseudo", "--out", "{long}"],
    ["reproduce", "--out", "{long}"], ["benchmark", "--suite", "standard", "--out", "{long}"],
], ids=lambda argv: " ".join(a for a in argv[:2]))
def test_a_path_too_long_is_one_line_for_every_command(tmp_path, monkeypatch, capsys, argv):
    (tmp_path / "s.toml").write_text(SWEEP)
    monkeypatch.chdir(tmp_path)
    assert main([a.format(long="z" * 300) for a in argv]) == 2
    one_line(capsys, "File name too long", "zzz")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


# ---- 4 and 9. the store's own files ---------------------------------------------------

@pytest.fixture(scope="module")
def finished_store(tmp_path_factory) -> Path:
    """A one-run store, made once by the command in a new process."""
    folder = tmp_path_factory.mktemp("store")
    (folder / "s.toml").write_text(SWEEP)
    subprocess.run([sys.executable, "-m", "armtransfer.cli", "sweep", "s.toml", "--out", "store", "--workers", "1"],
                   cwd=folder, check=True, capture_output=True)
    return folder / "store"


@pytest.fixture
def store(finished_store, tmp_path) -> Path:
    shutil.copytree(finished_store, tmp_path / "store", symlinks=True)
    return tmp_path / "store"


def _meta(change):
    def edit(store: Path) -> None:
        data = json.loads((store / "sweep.json").read_text())
        change(data)
        (store / "sweep.json").write_text(json.dumps(data))
    return edit


def _failed(key):
    def edit(store: Path) -> None:
        (run,) = (store / "runs").glob("*.json")
        record = json.loads(run.read_text())
        (store / "failed" / run.name).write_text(json.dumps({"key": key, "config": record["config"], "error": "x"}))
    return edit


STORE_EDITS = {
    "no spec": (_meta(lambda m: m.pop("spec")), ["sweep.json", "'spec' is missing"]),
    "spec a string": (_meta(lambda m: m.__setitem__("spec", "x")), ["sweep.json", "'spec' must be a table"]),
    "seeds [x]": (_meta(lambda m: m["spec"].__setitem__("seeds", ["x"])), ["sweep.json", "seeds", "'x'"]),
    "a spec without its key": (_meta(lambda m: m["spec"].__setitem__("trials", 2)), ["sweep.json", "does not match"]),
    "an unknown spec key": (_meta(lambda m: m["spec"].__setitem__("bogus", 1)), ["sweep.json", "'bogus'"]),
    "name a list": (_meta(lambda m: m.__setitem__("name", [1])), ["sweep.json", "'name'"]),
    "failed key a list": (_failed([1]), ["failed", "field 'key'"]),
    "failed key a number": (_failed(3), ["failed", "field 'key'"]),
    "failed record not JSON": (lambda s: (s / "failed" / "x.json").write_text("{"), ["failed", "not valid JSON"]),
}


@pytest.mark.parametrize("edit", list(STORE_EDITS))
def test_a_store_file_is_checked_on_read_naming_the_file_and_field(store, capsys, edit):
    from armtransfer.experiments.store import ResultStore, StoreError

    change, words = STORE_EDITS[edit]
    change(store)
    with pytest.raises(StoreError) as err:
        ResultStore.open_existing(store).to_frame()
    assert "\n" not in str(err.value) and all(w in str(err.value) for w in words), err.value
    before = sorted(p.name for p in store.rglob("*"))
    assert main(["summarize", str(store)]) == 2
    one_line(capsys, *words)
    assert sorted(p.name for p in store.rglob("*")) == before


@pytest.mark.parametrize("field,value", [("method", "pseudo"), ("seed", 1), ("trials", 5)])
def test_a_run_file_that_does_not_match_its_key_is_set_aside(store, capsys, field, value):
    from armtransfer.experiments.store import ResultStore

    (run,) = (store / "runs").glob("*.json")
    record = json.loads(run.read_text())
    record["config"][field] = value
    run.write_text(json.dumps(record))
    assert ResultStore.open_existing(store).records() == []
    assert "does not match its key" in capsys.readouterr().err
    assert (store / "bad" / run.name).is_file()


# ---- 5 and 6. stdout --------------------------------------------------------------------

@pytest.mark.parametrize("argv,redirect", [
    (["--version"], ">/dev/full"), (["--help"], ">/dev/full"), (["sweep", "--help"], ">/dev/full"),
    (["rooms", "--trials", "1"], ">/dev/full"), (["--version"], ">&-"), (["rooms", "--trials", "1"], ">&-"),
])
def test_stdout_that_cannot_be_written_is_one_line_and_a_non_zero_exit(tmp_path, argv, redirect):
    import shlex

    line = f"{shlex.quote(sys.executable)} -m armtransfer.cli {' '.join(argv)} {redirect}"
    proc = subprocess.run(["bash", "-c", line], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and "stdout" in lines[0], proc.stderr
    assert list(tmp_path.iterdir()) == []


def test_an_ascii_stdout_gets_non_ascii_names_escaped(tmp_path):
    (tmp_path / "s.toml").write_text(SWEEP)
    env = {**os.environ, "PYTHONIOENCODING": "ascii", "LC_ALL": "C"}
    proc = subprocess.run([sys.executable, "-m", "armtransfer.cli", "sweep", "s.toml", "--out", "r\u00e9sum\u00e9",
                           "--workers", "1"], cwd=tmp_path, capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0 and "r\\xe9sum\\xe9" in proc.stdout, proc.stderr
    assert (tmp_path / "r\u00e9sum\u00e9" / "sweep.json").is_file()


# ---- 7. a refusal before the work, nothing left ---------------------------------------

def test_a_store_whose_runs_take_no_files_is_refused_before_any_run(store, capsys, monkeypatch):
    from armtransfer.experiments import engines

    for run in (store / "runs").glob("*.json"):
        run.unlink()
    (store / "runs").rmdir()
    os.symlink("/sys", store / "runs")  # root cannot write there either
    (store.parent / "s.toml").write_text(SWEEP)
    timing = next((store / "timings").glob("*.json")).read_bytes()
    monkeypatch.setattr(engines.Tabular, "trials", lambda *a, **k: pytest.fail("a run started"))
    monkeypatch.chdir(store.parent)
    assert main(["sweep", "s.toml", "--out", "store", "--workers", "1"]) == 2
    one_line(capsys, "runs", "does not take new files")
    assert next((store / "timings").glob("*.json")).read_bytes() == timing


@pytest.mark.parametrize("out", ["new/store", "empty", "empty-with-lock"])
def test_a_store_that_cannot_be_opened_leaves_nothing_it_made(tmp_path, monkeypatch, out):
    from armtransfer.experiments import store as stores
    from armtransfer.experiments.sweep import load

    (tmp_path / "s.toml").write_text(SWEEP)
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty-with-lock").mkdir()
    (tmp_path / "empty-with-lock" / ".lock").write_text("")
    before = sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*"))

    def full(path, data):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))

    monkeypatch.setattr(stores, "write_json_atomic", full)
    with pytest.raises(OSError):
        stores.ResultStore.open_for(tmp_path / out, load(tmp_path / "s.toml"))
    assert sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*")) == before


# ---- 8. arm names ----------------------------------------------------------------------

@pytest.mark.parametrize("name,words", [
    ("planar2", "name of a built-in robot"), ("fine", "name of a built-in robot"), ("custom", "built-in"),
    ("gen", "built-in"), ("a:b", "NAME:ACTIONS"), ("a\nb", "letters, digits"), ("a b", "letters"),
    ("a,b", "letters"), ("-a", "not starting with"), ("n" * 400, "400 characters"), ("", "letters"), (3, "letters"),
])
def test_an_arm_name_must_be_writable_as_name_actions_and_not_a_built_in(scara_xml, name, words):
    from armtransfer.tasks.arms import arm_robot, check_arm_name

    with pytest.raises(ArmModelError) as err:
        check_arm_name(name, "--arm-name")
    assert words in str(err.value) and "\n" not in str(err.value)
    if isinstance(name, str) and name:  # the same through the API, and as the file's model attribute
        with pytest.raises(ArmModelError, match="arm_name|--arm-name"):
            arm_robot(None, "joint", xml_path=scara_xml, tip_site="pen_tip", arm_name=name)
        named = scara_xml.with_name("named.xml")
        named.write_text(scara_xml.read_text().replace('model="my_scara"', f'model="{name}"'))
        with pytest.raises(ArmModelError, match="model attribute"):
            arm_robot(None, "joint", xml_path=named, tip_site="pen_tip")


@pytest.mark.parametrize("name", ["my_scara", "ur5e-2.0", "A+B", "_x"])
def test_a_valid_arm_name_is_kept(name):
    from armtransfer.tasks.arms import check_arm_name

    assert check_arm_name(name, "--arm-name") == name


def test_a_sweep_arm_table_name_is_checked(tmp_path):
    from armtransfer.experiments.sweep import SweepFileError, normalise

    raw = {"arms": {"my arm": {"xml": "a.xml"}},
           "sweep": {"tasks": [1], "pairs": [["coarse", "my arm:joint"]], "methods": ["none"]}}
    with pytest.raises(SweepFileError, match="letters, digits"):
        normalise(raw)


# ---- 9. the remaining API gaps ---------------------------------------------------------

@pytest.mark.parametrize("env_id", ["armtransfer/Rooms-v0", "armtransfer/ArmRooms-v0",
                                    "armtransfer/ContinuousArmRooms-v0", "armtransfer/ContinuousArmRoomsBox-v0"])
@pytest.mark.parametrize("options,words", [({"bogus": 1}, "'bogus'"), ([1], "must be a dict")])
def test_reset_refuses_options_it_cannot_use(env_id, options, words):
    import gymnasium as gym

    import armtransfer  # noqa: F401  (registers the environments)

    env = gym.make(env_id)
    env.reset(seed=0, options={})
    env.reset(seed=0, options=None)
    with pytest.raises(InvalidParameterError, match=words):
        env.reset(seed=0, options=options)


def test_arms_generate_refuses_a_non_empty_out_before_drawing(tmp_path, capsys):
    (tmp_path / "g").mkdir()
    (tmp_path / "g" / "mine.txt").write_text("keep\n")
    assert main(["arms", "generate", "--family", "planar", "--dof", "2", "--out", str(tmp_path / "g")]) == 2
    one_line(capsys, "not empty")
    assert [p.name for p in (tmp_path / "g").iterdir()] == ["mine.txt"]

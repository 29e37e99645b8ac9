"""Every cache file is checked on read and rebuilt when it is not what it claims: arm cache
entries that are directories, FIFOs or arrays out of range, mount choices of the wrong shape
or that do not hold, generated-arm files edited or lost; and the cache key covers every file
MuJoCo reads for the arm (includes, meshes), reading nothing else."""

import json
import os
import time

import numpy as np
import pytest

from armtransfer.errors import ArmModelError
from armtransfer.ik import cache as _cache
from armtransfer.tasks import arms
from armtransfer.tasks.arms import arm_robot
from contract import FORE, INCLUDING

POSE = dict(tip_site="pen_tip", base_pos=(-0.15, -0.02, -0.002), base_yaw=0.0)



@pytest.fixture
def own_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("ARMTRANSFER_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _entry(robot) -> "os.PathLike":
    return _cache.entry_path(robot.name, robot.arm.key)


@pytest.mark.parametrize("kind", [pytest.param("directory", marks=pytest.mark.slow), pytest.param("fifo", marks=pytest.mark.slow),
                                  pytest.param("garbage", marks=pytest.mark.slow), "wrong arrays"])  # 3-5 s each
def test_a_cache_entry_that_is_not_an_entry_is_rebuilt(kind, own_cache, scara_xml):
    first = arm_robot(None, "cartesian", xml_path=scara_xml, **POSE)
    entry = _entry(first)
    if kind == "wrong arrays":  # a well-formed entry with its checksum, whose states are out of range
        with np.load(entry) as f:
            arrays = {k: f[k] for k in f.files if not k.startswith("__")}
        arrays["next_state"] = arrays["next_state"] + len(arrays["label"])
        _cache.save(first.name, first.arm.key, arrays)
    else:
        os.unlink(entry)
        {"directory": os.mkdir, "fifo": os.mkfifo, "garbage": lambda p: open(p, "w").write("x")}[kind](entry)
    t0 = time.monotonic()
    again = arm_robot(None, "cartesian", xml_path=scara_xml, **POSE)
    assert time.monotonic() - t0 < 120  # a FIFO read would hang
    assert again.arm.cache == "corrupt"
    assert np.array_equal(again.next_state, first.next_state)
    assert arm_robot(None, "cartesian", xml_path=scara_xml, **POSE).arm.cache == "hit"


@pytest.mark.slow
def test_a_lock_that_is_a_fifo_does_not_hang(own_cache, scara_xml):
    first = arm_robot(None, "cartesian", xml_path=scara_xml, **POSE)
    entry = _entry(first)
    os.unlink(entry)
    lock = entry.with_name(entry.name + ".lock")
    lock.unlink()
    os.mkfifo(lock)
    assert arm_robot(None, "cartesian", xml_path=scara_xml, **POSE).arm.cache == "miss"


def test_an_edited_include_is_a_new_arm(own_cache, tmp_path):
    (tmp_path / "fore.xml").write_text(FORE.format(length=0.2))
    path = tmp_path / "inc.xml"
    path.write_text(INCLUDING.format(meshdir="."))
    wide = arm_robot(None, "cartesian", xml_path=path, **POSE)
    assert arm_robot(None, "cartesian", xml_path=path, **POSE).arm.cache == "hit"
    (tmp_path / "fore.xml").write_text(FORE.format(length=0.12))
    narrow = arm_robot(None, "cartesian", xml_path=path, **POSE)
    assert narrow.arm.cache == "miss" and narrow.arm.key != wide.arm.key
    assert narrow.n_states != wide.n_states


def test_the_key_reads_the_model_files_not_the_mesh_folder(own_cache, tmp_path):
    (tmp_path / "fore.xml").write_text(FORE.format(length=0.2))
    path = tmp_path / "inc.xml"
    path.write_text(INCLUDING.format(meshdir="/"))
    t0 = time.monotonic()
    key = arms._assets_sha(path)
    assert time.monotonic() - t0 < 5  # meshdir="/" was walked whole
    assert key == arms._assets_sha(path)
    from armtransfer.ik.scene import model_files

    assert [p.name for p in model_files(path)] == ["inc.xml", "fore.xml"]


MOUNT = dict(tip_site="pen_tip")


@pytest.mark.slow
@pytest.mark.parametrize("bad", [[], {"pos": [1]}, {"pos": [50, 0, 0]}, {"yaw": "x"}, {"reach": 2}, "dir", "fifo"])
def test_a_mount_choice_that_does_not_hold_is_chosen_again(bad, own_cache, scara_xml):
    chosen = arm_robot(None, "cartesian", xml_path=scara_xml, **MOUNT)
    (entry,) = own_cache.glob("mount-*.json")
    data = json.loads(entry.read_text())
    entry.unlink()
    if bad == "dir":
        entry.mkdir()
    elif bad == "fifo":
        os.mkfifo(entry)
    else:
        entry.write_text(json.dumps(bad if isinstance(bad, list) else {**data, **bad}))
    again = arm_robot(None, "cartesian", xml_path=scara_xml, **MOUNT)
    assert again.arm.mount == chosen.arm.mount
    assert json.loads(entry.read_text())["pos"] == data["pos"]


def test_a_malformed_generated_arm_file_is_named(tmp_path, scara_xml):
    sidecar = scara_xml.with_suffix(".json")
    sidecar.write_text(json.dumps({"format": arms.SIDECAR_FORMAT, "mount_pos": [0.1], "mount_yaw": 0,
                                   "tip_down": True, "joint_step": None}))
    with pytest.raises(ArmModelError, match="generated arm's file .*mount_pos"):
        arms.read_sidecar(scara_xml)
    sidecar.write_text(json.dumps({"format": "someone-else/1"}))
    assert arms.read_sidecar(scara_xml) is None

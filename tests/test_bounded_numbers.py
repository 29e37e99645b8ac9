"""Every reader of a user's numbers is bounded (digits, magnitude, finiteness), every spec's
integer is read by one grammar, every network address is checked before it is used, and a
world file cannot take a built-in world's name: each a one-line error, before anything is
written."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import armtransfer
from armtransfer.checks import integer_text
from armtransfer.cli import main
from armtransfer.errors import ArmTransferError, InvalidParameterError, InvalidWorldError
from armtransfer.experiments import sweep as sweeps
from armtransfer.io import check_user_numbers, parse_json_bytes, parse_toml_bytes
from armtransfer.parallel.executors import ExecutorError, check_address
from armtransfer.worlds.resolve import world

ROOMS11 = (Path(armtransfer.__file__).parent / "worlds" / "data" / "rooms11.toml").read_text()


@pytest.mark.parametrize("text, accepted", [
    ("0", 0), ("42", 42), ("-8", -8), ("+3", 3), ("9" * 40, int("9" * 40)),
    ("²", None), ("٣", None), ("1_000", None), (" 3", None), ("3 ", None), ("", None), ("9" * 41, None),
    ("1e3", None), ("0x10", None), ("-", None),
])
def test_one_integer_grammar(text, accepted):
    """What int() would refuse ('²') or read otherwise than it looks ('٣', '1_000') is refused."""
    assert integer_text(text) == accepted
    if accepted is not None:
        assert int(text) == accepted  # never more than int() accepts


@pytest.mark.parametrize("raw, said", [
    (b"[sweep]\nseeds = [" + b"7" * 5000 + b"]\n", "holds a number that cannot be read"),
    (b"[sweep]\nseeds = [" + b"7" * 30 + b"]\n", "holds an integer of 30 digits"),
    (b"[sweep]\nwind = [nan]\n", "holds the number nan"),
    (b"[sweep]\nK = [1e999]\n", "holds the number inf"),
])
def test_toml_numbers_are_bounded_as_the_file_is_read(tmp_path, raw, said):
    with pytest.raises(ValueError, match=said):
        parse_toml_bytes(raw)
    (tmp_path / "s.toml").write_bytes(raw)
    with pytest.raises(sweeps.SweepFileError, match=said) as err:
        sweeps.load(tmp_path / "s.toml")
    assert "\n" not in str(err.value)


def test_json_numbers_are_bounded_as_the_file_is_read(tmp_path):
    with pytest.raises(ValueError, match="holds an integer of 5000 digits"):
        parse_json_bytes(b'{"a": ' + b"1" * 5000 + b"}")
    with pytest.raises(ValueError, match="holds the number inf"):
        check_user_numbers(parse_json_bytes(b'{"a": [1, {"b": 1e999}]}'))
    (tmp_path / "w.json").write_text('{"name": ' + "9" * 4400 + "}")
    with pytest.raises(InvalidWorldError, match=r"^world file .*w.json' holds an integer of 4400 digits"):
        world(str(tmp_path / "w.json"))


def test_a_spec_with_a_superscript_digit_is_one_line(capsys):
    for spec in ("generated:²", "generated:1:¹⁵", "generated: 3", "generated:" + "1" * 19):
        with pytest.raises(InvalidWorldError, match="a generated world is generated:SEED"):
            world(spec)
    with pytest.raises(ArmTransferError):  # the API raises the package's error, not a bare ValueError
        armtransfer.transfer(world="generated:²")
    assert main(["rooms", "--world", "generated:²", "--trials", "1"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "generated:SEED" in err


@pytest.mark.parametrize("address, said", [
    ("a" * 64 + ":6379", r"has 64 characters \(at most 63\)"),
    ("ray://" + "b" * 70 + ".lan:10001", "has 70 characters"),
    ("host:0", "a port 1..65535"),
    ("host:²", "a port 1..65535"),
    ("host", "a port 1..65535"),
    ("bad_host:6379", "is not a host name"),
    ("[::1x]:6379", "is not an IPv6 address"),
    ("x." * 130 + "y:1", "is not a host name"),
])
def test_a_network_address_is_checked_before_use(address, said):
    with pytest.raises(ExecutorError, match=said):
        check_address(address)
    assert check_address("auto") is None
    assert check_address("10.0.0.2:6379") == ("10.0.0.2", 6379)
    assert check_address("ray://head-1.example.org:10001") == ("head-1.example.org", 10001)
    assert check_address("[::1]:6379") == ("::1", 6379)


@pytest.mark.parametrize("name", ["rooms", "rooms11", "ROOMS15", "generated:3", "generated:7:15"])
def test_a_layout_file_cannot_take_a_built_in_worlds_name(tmp_path, name):
    path = tmp_path / "w.toml"
    path.write_text(ROOMS11.replace('name = "rooms11"', f"name = {json.dumps(name)}"))
    with pytest.raises(InvalidWorldError, match=rf"name {name!r} is a built-in world's"):
        world(str(path))
    path.write_text(ROOMS11.replace('name = "rooms11"', 'name = "my-rooms"'))
    assert world(str(path)).name == "my-rooms"


def test_the_api_and_the_command_line_take_the_same_numbers(capsys):
    """A count is an integer everywhere (numpy's too); a real number may be numpy's."""
    for options in ({"trials": 1.0}, {"max_total_steps": 1e3}, {"max_episodes": np.float64(5)}, {"seed": 2**70},
                    {"step_reward": -1e308}, {"goal_reward": 1e308}, {"K": 1e308}, {"K": np.float32("inf")}):
        with pytest.raises(InvalidParameterError):
            armtransfer.transfer(**options)
    for argv in (["--trials", "1.0"], ["--max-episodes", "1e3"], ["--seed", str(2**70)], ["--step-reward=-1e308"],
                 ["--K", "1e308"]):
        code = None
        try:
            code = main(["rooms", *argv])
        except SystemExit as exit_:
            code = exit_.code
        assert code == 2, argv
        assert len(capsys.readouterr().err.strip().splitlines()) == 1
    r = armtransfer.transfer(methods=["pseudo"], trials=np.int64(1), max_episodes=np.int32(20), K=np.float32(0.01),
                             trajectory="optimal", controls=False)
    assert r.trials == 1


def test_a_stored_seed_the_command_line_refuses_is_refused_on_read(tmp_path, capsys):
    path = tmp_path / "results.json"
    path.write_text(json.dumps({"suite": {"name": "fast"}, "seed": 2**70, "methods": [], "not_in_registry": [],
                                "records": [], "summary": {}}))
    assert main(["summarize", str(path), "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert "field 'seed' is 1180591620717411303424, which no benchmark takes" in err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "r").exists()

"""Every count, range and length has a bound checked before anything is built from it:
integers far past any run, task ranges in the billions, metres far past any table, deep
nesting. Property-based: the whole range of values past each bound is refused in one line."""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import armtransfer.checks as checks
from contract import refused
from armtransfer.errors import ArmModelError, ArmTransferError, InvalidParameterError
from armtransfer.ik.tool import Tool
from armtransfer.learning.config import LearnerConfig

SETTINGS = settings(max_examples=30, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])


COUNT_FLAGS = ["--max-episode-steps", "--max-total-steps", "--max-episodes", "--patience", "--trials", "--seed",
               "--max-span"]


@SETTINGS
@given(flag=st.sampled_from(COUNT_FLAGS), value=st.integers(min_value=checks.MAX_COUNT + 1, max_value=10**400))
def test_a_count_past_any_run_is_refused_before_learning(flag, value, tmp_path, monkeypatch, capsys):
    refused(["rooms", flag, str(value), "--json", "o.json"], tmp_path, monkeypatch, capsys)


@SETTINGS
@given(field=st.sampled_from(["max_episodes", "patience"]), value=st.integers(1_000_001, 10**30))
def test_counts_that_size_arrays_are_bounded_tighter(field, value):
    with pytest.raises(InvalidParameterError, match=field):
        LearnerConfig(**{field: value})


@SETTINGS
@given(field=st.sampled_from(["max_total_steps", "max_episode_steps", "max_episodes"]),
       value=st.integers(1, 1_000_000), kind=st.sampled_from([np.int64, np.int32, np.uint32, int]))
def test_counts_in_range_are_taken_whatever_their_integer_type(field, value, kind):
    config = LearnerConfig(**{field: kind(value)})
    assert getattr(config, field) == value and type(getattr(config, field)) is int


@SETTINGS
@given(value=st.one_of(st.floats(allow_nan=True, allow_infinity=True).filter(lambda v: not math.isfinite(v)),
                       st.floats(min_value=checks.MAX_METRES * 1.0001, max_value=1e308),
                       st.floats(max_value=-checks.MAX_METRES * 1.0001, min_value=-1e308)),
       axis=st.integers(0, 2))
def test_a_tool_offset_far_past_any_arm_isrefused(value, axis):
    offset = [0.0, 0.0, 0.0]
    offset[axis] = value
    with pytest.raises(ArmModelError, match="tip offset"):
        Tool(site="tip", offset=tuple(offset))


@SETTINGS
@given(value=st.floats(min_value=checks.MAX_METRES * 1.0001, max_value=1e308), sign=st.sampled_from([1, -1]))
def test_a_base_position_far_past_any_table_is_refused_on_the_command_line(value, sign, tmp_path, monkeypatch,
                                                                           capsys, scara_xml):
    err = refused(["arms", "list", "--arm", "planar2", "--arm-xml", str(scara_xml), "--tip-site", "pen_tip",
                    f"--base-pos=0,0,{sign * value!r}"], tmp_path, monkeypatch, capsys)
    assert "base position" in err


@SETTINGS
@given(hi=st.integers(min_value=5, max_value=10**30))
def test_a_task_range_is_checked_before_it_is_listed(hi, tmp_path, monkeypatch, capsys):
    err = refused(["matrix", "--robots", "coarse,fine", "--tasks", f"1-{hi}", "--out", "m"], tmp_path, monkeypatch,
                   capsys)
    assert "unknown task" in err and "valid tasks: 1, 2, 3, 4" in err


@settings(max_examples=6, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(depth=st.integers(min_value=1_000, max_value=20_000), brackets=st.sampled_from(["[]", "{}"]))
def test_deeply_nested_toml_is_one_line(depth, brackets, tmp_path, monkeypatch, capsys):
    body = "[" * depth + "]" * depth if brackets == "[]" else "{a=" * depth + "1" + "}" * depth
    (tmp_path / "deep.toml").write_text(f"[sweep]\nx = {body}\n")
    err = refused(["sweep", "deep.toml", "--out", "st"], tmp_path, monkeypatch, capsys)
    assert "nests too deeply" in err or "not valid TOML" in err
    (tmp_path / "deep.toml").unlink()


@SETTINGS
@given(value=st.one_of(st.integers(min_value=checks.MAX_TRIALS + 1, max_value=10**40), st.integers(max_value=0)))
def test_the_api_bounds_trials(value):
    import armtransfer

    with pytest.raises(ArmTransferError, match="trials"):
        armtransfer.transfer(trials=value)

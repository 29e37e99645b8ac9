"""Action sequence mapping on hand-made cases whose answer is known, and its reuse."""

import json

import numpy as np
import pytest

from armtransfer.cli import main
from armtransfer.errors import InvalidMappingError
from armtransfer.tasks.catalog import table_task
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.worlds.layout import ROOMS, Layout
from armtransfer.learning import reference, methods, sarsa
from armtransfer.experiments import experiment
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.mapping import ActionMapping, MacroTable, chain, load_for

# A 7 x 7 open world (no walls) and the 7 x 7 two-room world of test_sarsa.
OPEN = Layout(lo=-3, hi=3, walls=(), doors=())
SMALL = Layout(lo=-3, hi=3, walls=(((0, -3), (0, 3)),), doors=((0, 2),))
F, B, R, L = 0, 1, 2, 3  # fine actions; the coarse ones are 1..4 = 0..3 in the same directions


def fine_path(robot, layout, start, moves):
    """A path [(state, action), ..., (goal, -1)] of ``robot`` from ``start`` by ``moves``."""
    s = robot.start_state(layout.cell(*start))
    path = []
    for a in moves:
        path.append((s, a))
        s = int(robot.next_state[s, a])
    path.append((s, -1))
    return path


def traj(layout, cells, actions, goal, source="coarse"):
    return trajectories.Trajectory(
        tuple(layout.cell(*c) for c in cells), tuple(actions), layout.cell(*goal), source
    )


def pair(layout=OPEN):
    return grid_robot("coarse", layout), grid_robot("fine", layout)


def test_coarse_up_maps_to_fine_forward_forward():
    coarse, fine = pair()
    t = traj(OPEN, [(-2, -2)], [0], (-2, 0))
    m = ActionMapping.for_robots(coarse, fine)
    assert m.learn_from(fine, fine_path(fine, OPEN, (-2, -2), [F, F]), t) == 1
    assert m.get([0]) == (F, F)
    assert m.names([0], "source") == "1" and m.names(m.get([0]), "target") == "F F"


def test_every_consecutive_match_and_longer_spans_give_entries():
    coarse, fine = pair()
    # coarse: up, right, up; fine: F F R R F F
    t = traj(OPEN, [(-2, -2), (-2, 0), (0, 0)], [0, 2, 0], (0, 2))
    path = fine_path(fine, OPEN, (-2, -2), [F, F, R, R, F, F])
    m = ActionMapping.for_robots(coarse, fine)
    m.learn_from(fine, path, t, max_span=2)
    assert m.get([0]) == (F, F) and m.entries[(0,)].count == 2
    assert m.get([2]) == (R, R)
    assert m.get([0, 2]) == (F, F, R, R) and m.get([2, 0]) == (R, R, F, F)
    assert m.get([0, 2, 0]) is None  # longer than max_span
    m3 = ActionMapping.for_robots(coarse, fine)
    m3.learn_from(fine, path, t, max_span=3)
    assert m3.get([0, 2, 0]) == (F, F, R, R, F, F)


def test_a_loop_in_the_source_maps_to_no_action():
    coarse, fine = pair()
    # coarse goes up and comes back down (a loop), then right; fine goes right at once
    t = traj(OPEN, [(-2, -2), (-2, 0), (-2, -2)], [0, 1, 2], (0, -2))
    path = fine_path(fine, OPEN, (-2, -2), [R, R])
    assert chain([*t.cells, t.goal], [int(fine.label[s]) for s, _ in path]) == [(0, 0), (2, 0), (3, 2)]
    m = ActionMapping.for_robots(coarse, fine)
    m.learn_from(fine, path, t)
    assert m.get([0, 1]) == ()  # "no action"
    assert m.get([2]) == (R, R)
    assert m.get([0, 1, 2]) == (R, R)
    assert m.names((), "target") == "-"


def test_the_shorter_target_sequence_wins_whichever_comes_first():
    coarse, fine = pair()
    t = traj(OPEN, [(-2, -2)], [0], (-2, 0))
    detour = fine_path(fine, OPEN, (-2, -2), [R, F, F, L])
    direct = fine_path(fine, OPEN, (-2, -2), [F, F])
    for order in ([detour, direct], [direct, detour]):
        m = ActionMapping.for_robots(coarse, fine)
        for p in order:
            m.learn_from(fine, p, t)
        assert m.get([0]) == (F, F) and m.entries[(0,)].count == 2
    # merging keeps the shorter too, and adds the counts
    a, b = ActionMapping.for_robots(coarse, fine), ActionMapping.for_robots(coarse, fine)
    a.learn_from(fine, detour, t)
    b.learn_from(fine, direct, t)
    b.learn_from(fine, direct, t)
    a.merge(b)
    assert a.get([0]) == (F, F) and a.entries[(0,)].count == 3
    # an equally long sequence seen later does not replace the first
    a.add([0], [B, B])
    assert a.get([0]) == (F, F)


def test_json_round_trip_keeps_everything(tmp_path):
    coarse, fine = pair()
    m = ActionMapping.for_robots(coarse, fine)
    m.add([0], [F, F], count=3)
    m.add([0, 1], [])
    m.add([3, 3, 0], [L, L, L, F, L, F])
    path = tmp_path / "sub" / "m.json"
    m.save(path)
    data = json.loads(path.read_text())
    assert data["source"] == "coarse" and data["target"] == "fine"
    assert {"key": [0], "target": [0, 0], "count": 3}.items() <= data["entries"][0].items()
    back = ActionMapping.load(path)
    assert back == m
    assert back.entries[(0, 1)].target == () and back.entries[(0,)].count == 3
    assert back.source_actions == ("1", "2", "3", "4") and back.target_actions == ("F", "B", "R", "L")


def test_a_mapping_for_another_robot_pair_is_refused(tmp_path):
    coarse, fine = pair(ROOMS)
    path = tmp_path / "m.json"
    m = ActionMapping.for_robots(coarse, fine)
    m.add([0], [F, F])
    m.save(path)
    assert load_for(path, coarse, fine) == m
    with pytest.raises(InvalidMappingError, match="coarse -> fine, not fine -> coarse"):
        load_for(path, fine, coarse)
    with pytest.raises(InvalidMappingError, match="for fine -> coarse, not coarse -> fine"):
        ActionMapping.for_robots(fine, coarse).merge(m)
    with pytest.raises(InvalidMappingError, match="target robot is fine, not coarse"):
        MacroTable(m, trajectories.shortest(fine, ROOMS.cell(0, 0), ROOMS.cell(4, 4)), coarse)
    assert len(load_for(tmp_path / "absent.json", coarse, fine)) == 0


@pytest.mark.parametrize("text,message", [
    ("{oops", "not valid JSON"),
    ("[]", "expected a JSON object"),
    ('{"format": "x"}', "'format' must be"),
    ('{"format": "armtransfer-mapping/1", "source": "coarse", "target": "fine", "entries": [{"key": [], "target": [], "count": 1}]}', "key must be"),
    ('{"format": "armtransfer-mapping/1", "source": "coarse", "target": "fine", "entries": [{"key": [0], "target": [-1], "count": 1}]}', "target must be"),
    ('{"format": "armtransfer-mapping/1", "source": "coarse", "target": "fine", "entries": [{"key": [0], "target": [], "count": 0}]}', "count must be"),
    ('{"format": "armtransfer-mapping/1", "source": "coarse", "target": "fine", "entries": [{"key": [0], "target": [], "count": 1}, {"key": [0], "target": [1], "count": 1}]}', "repeats the key"),
    ('{"format": "armtransfer-mapping/1", "source": "coarse", "target": "fine", "entries": [{"key": [0], "target": [7], "count": 1}]}', "has 4 actions"),
])
def test_malformed_mapping_files_are_one_line_errors(tmp_path, text, message):
    path = tmp_path / "m.json"
    path.write_text(text)
    coarse, fine = pair(ROOMS)
    with pytest.raises(InvalidMappingError, match=message) as exc:
        load_for(path, coarse, fine)
    assert "\n" not in str(exc.value)


def test_macro_table_takes_the_longest_key_with_a_sequence_and_the_last_position():
    coarse, fine = pair()
    m = ActionMapping.for_robots(coarse, fine)
    m.add([0], [F, F])
    m.add([0, 0], [F, F, F, F])
    m.add([0, 1], [])  # a loop: nothing to run, so the shorter key is taken
    m.add([2], [R, R])
    t = traj(OPEN, [(-2, -2), (-2, 0), (-2, 2), (-2, 0), (0, 0)], [0, 0, 1, 2, 2], (2, 0))
    table = MacroTable(m, t, fine)
    by_xy = {OPEN.xy(c): (mac.position, mac.actions) for c, mac in table.by_cell.items()}
    assert by_xy[(-2, -2)] == (0, (F, F, F, F))
    assert by_xy[(-2, 0)] == (3, (R, R))
    assert (-2, 2) not in by_xy  # key "2" is not mapped, "2 3" neither
    assert by_xy[(0, 0)] == (4, (R, R))
    start, length, actions = table.arrays(fine)
    s = fine.start_state(OPEN.cell(-2, -2))
    assert actions[start[s] : start[s] + length[s]].tolist() == [F, F, F, F]
    assert length.sum() == 4 + 2 + 2


def test_mapped_fraction_counts_steps_inside_available_macros():
    coarse, fine = pair()
    m = ActionMapping.for_robots(coarse, fine)
    m.add([0], [F, F])
    t = traj(OPEN, [(-2, -2), (-2, 0)], [0, 2], (0, 0))
    table = MacroTable(m, t, fine)
    # F F (mapped at (-2,-2)) then R R (no macro for key "3")
    path = fine_path(fine, OPEN, (-2, -2), [F, F, R, R])
    assert table.mapped_segments(fine, path) == [(0, 2)]
    assert table.mapped_fraction(fine, path) == 0.5
    other = fine_path(fine, OPEN, (-2, -2), [R, F, F, L, R, R])
    assert table.mapped_fraction(fine, other) == 0.0
    assert MacroTable(ActionMapping.for_robots(coarse, fine), t, fine).mapped_fraction(fine, path) is None


@pytest.mark.parametrize("wind", [0.0, 0.2])
def test_kernel_runs_macros_bit_identically_to_the_dense_reference(wind):
    coarse, fine = pair(SMALL)
    start, goal = SMALL.cell(-2, -2), SMALL.cell(2, -2)
    t = trajectories.shortest(coarse, start, goal)  # up, up, right, right, down, down
    m = ActionMapping.for_robots(coarse, fine)
    m.add([0], [F, F])
    m.add([1], [B, B])
    m.add([2, 2], [L, L, R, R, R, R])  # runs into the border: abandoned when blocked
    table = MacroTable(m, t, fine, episodes=None)
    config = LearnerConfig(trace_cutoff=0.0, max_episodes=12, patience=1000)
    K = methods.get("pseudo").resolve_k("auto", config.step_reward, t)
    shaping = methods.build_shaping("mapping", fine, t, K, config.step_reward)
    s0 = fine.start_state(start)
    fast = sarsa.learn(fine, s0, goal, config, np.random.default_rng(11), shaping=shaping,
                       wind=wind, macros=table, keep_q=True)
    Q, steps = reference.learn(fine, s0, goal, config, np.random.default_rng(11), episodes=12,
                               traj=t, K=K, wind=wind, macros=table)
    assert fast.macro_steps.sum() > 0
    assert fast.episode_steps.tolist() == steps
    assert np.array_equal(fast.Q, Q)


def test_macros_are_offered_only_in_the_first_episodes_asked_for():
    coarse, fine = pair(SMALL)
    start, goal = SMALL.cell(-2, -2), SMALL.cell(2, -2)
    t = trajectories.shortest(coarse, start, goal)
    m = ActionMapping.for_robots(coarse, fine)
    m.add([0], [F, F])
    s0 = fine.start_state(start)
    config = LearnerConfig(max_episodes=5, patience=1000)
    one = sarsa.learn(fine, s0, goal, config, np.random.default_rng(0), macros=MacroTable(m, t, fine))
    assert one.macro_steps[0] > 0 and one.macro_steps[1:].sum() == 0
    every = sarsa.learn(fine, s0, goal, config, np.random.default_rng(0),
                        macros=MacroTable(m, t, fine, episodes=None))
    assert (every.macro_steps > 0).all()


def test_a_task_made_of_mapped_sequences_is_solved_far_sooner():
    coarse, fine = grid_robot("coarse"), grid_robot("fine")
    c = ROOMS.cell
    # learn on a short task in room 1: up 4 coarse steps, then right 4
    first = trajectories.shortest(coarse, c(0, 0), c(8, 8))
    m = ActionMapping.for_robots(coarse, fine)
    m.learn_from(fine, fine.shortest_path(fine.start_state(c(0, 0)), c(8, 8)), first)
    assert m.get([0]) == (F, F) and m.get([2]) == (R, R)
    # a new task whose trajectory is nothing but those keys, concatenated
    start, goal = c(2, -4), c(20, 20)
    new = trajectories.shortest(coarse, start, goal)
    assert set(new.actions) <= {0, 2}
    config = LearnerConfig(max_episodes=1)
    pseudo = experiment.run_method("pseudo", fine, start, goal, new, 8, 0, config)
    mapped, _ = experiment.run_mapping(fine, start, goal, new, m, 8, 0, config)
    p = np.mean(pseudo.column("exploration_steps"))
    q = np.mean(mapped.column("exploration_steps"))
    distance = len(fine.shortest_path(fine.start_state(start), goal)) - 1
    assert q < 0.2 * p
    assert q < 3 * distance


def test_run_mapping_learns_from_converged_trials_and_reports_the_fraction():
    coarse, fine = pair(SMALL)
    start, goal = SMALL.cell(-2, -2), SMALL.cell(2, -2)
    t = trajectories.shortest(coarse, start, goal)
    empty = ActionMapping.for_robots(coarse, fine)
    config = LearnerConfig()
    res, learned = experiment.run_mapping(fine, start, goal, t, empty, 3, 0, config)
    assert all(res.column("converged"))
    assert res.extra["mapped_fraction"] == [None] * 3  # nothing to map with yet
    assert len(empty) == 0 and len(learned) > 0  # the input is not changed
    assert learned.get([0]) == (F, F)
    res2, learned2 = experiment.run_mapping(fine, start, goal, t, learned, 3, 0, config)
    assert all(f is not None and 0.0 <= f <= 1.0 for f in res2.extra["mapped_fraction"])
    assert sum(e.count for e in learned2.entries.values()) > sum(e.count for e in learned.entries.values())


# ------------------------------------------------------------------------------- CLI


def test_rooms_method_mapping_learns_saves_and_reuses_the_mapping(tmp_path, capsys):
    mfile = tmp_path / "maps" / "coarse-fine.json"
    out1, out2 = tmp_path / "a.json", tmp_path / "b.json"
    args = ["rooms", "--method", "mapping", "--mapping", str(mfile), "--trials", "2"]
    assert main([*args, "--start", "0,0", "--goal", "6,8", "--json", str(out1)]) == 0
    printed = capsys.readouterr().out
    assert "no mapping was available" in printed and "equals 'pseudo'" in printed
    first = ActionMapping.load(mfile)
    assert (first.source, first.target) == ("coarse", "fine") and len(first) > 0
    d1 = json.loads(out1.read_text())
    assert d1["results"]["mapping"]["mapped_fraction"] == [None, None]
    assert d1["mapping"]["entries_before"] == 0 and d1["mapping"]["entries_after"] == len(first)

    assert main([*args, "--start", "0,0", "--goal", "8,10", "--json", str(out2)]) == 0
    printed = capsys.readouterr().out
    assert "macros at" in printed and "saved to" in printed
    d2 = json.loads(out2.read_text())
    fr = d2["results"]["mapping"]["mapped_fraction"]
    assert len(fr) == 2 and all(f is None or 0.0 <= f <= 1.0 for f in fr)
    assert d2["mapping"]["macro_states"] > 0
    second = ActionMapping.load(mfile)
    assert sum(e.count for e in second.entries.values()) > sum(e.count for e in first.entries.values())


def test_rooms_mapping_without_a_file_says_so(capsys):
    assert main(["rooms", "--start", "0,0", "--goal", "4,4", "--method", "pseudo", "mapping", "--trials", "1"]) == 0
    printed = capsys.readouterr().out
    assert "no mapping was available (no mapping file given)" in printed
    assert "not saved" in printed


def _one_line_exit_2(args, capsys, message):
    code = main(args)
    err = capsys.readouterr().err
    assert code == 2
    assert message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_rooms_refuses_a_mapping_for_another_robot_pair(tmp_path, capsys):
    mfile = tmp_path / "m.json"
    m = ActionMapping.for_robots(grid_robot("fine"), grid_robot("coarse"))
    m.add([0, 0], [0])
    m.save(mfile)
    before = mfile.read_bytes()
    _one_line_exit_2(["rooms", "--task", "1", "--method", "mapping", "--mapping", str(mfile), "--trials", "1"],
                     capsys, "the mapping is for fine -> coarse, not coarse -> fine")
    assert mfile.read_bytes() == before  # untouched


def test_rooms_mapping_bad_input(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text("{nope")
    _one_line_exit_2(["rooms", "--method", "mapping", "--mapping", str(bad), "--trials", "1"], capsys, "not valid JSON")
    _one_line_exit_2(["rooms", "--method", "pseudo", "--mapping", str(bad), "--trials", "1"], capsys,
                     "--mapping goes with --method mapping")
    blocker = tmp_path / "file"
    blocker.write_text("x")
    _one_line_exit_2(["rooms", "--method", "mapping", "--mapping", str(blocker / "m.json"), "--trials", "1"],
                     capsys, "cannot write")


@pytest.mark.slow
def test_reproduce_reports_the_mapping_columns_beside_the_papers(reproduce_fast):
    code, out = reproduce_fast
    assert code == 0
    report = (out / "report.md").read_text()
    for heading in ("Table II D-F", "Table V D-E", "Table III analog: coarse -> fine",
                    "Table III analog: fine -> coarse", "under wind 0.01", "Fig. 7 analog"):
        assert heading in report, heading
    assert "1,039.6" in report and "85.83" in report  # the paper's D and F for task 2
    assert (out / "fig7_mapping.png").stat().st_size > 1000
    res = json.loads((out / "results.json").read_text())
    for key in ("mapping_coarse_fine", "mapping_fine_coarse", "mapping_wind"):
        tasks = res[key]["tasks"]
        assert tasks["1"]["entries_before"] == 0 < tasks["2"]["entries_before"] <= tasks["4"]["entries_before"]
        assert tasks["2"]["ci95"] is not None and tasks["2"]["improvement_ci95"] is not None
        m = ActionMapping.load(out / f"{key}.json")
        assert len(m) == tasks["4"]["entries_after"]
    # task 1 has no mapping yet: it is the pseudo method, bit for bit
    assert res["mapping_coarse_fine"]["tasks"]["1"]["exploration_steps"] == \
        res["table_ii"]["1"]["results"]["pseudo"]["exploration_steps"]


def test_macros_in_every_episode_keep_the_greedy_path_from_converging():
    """Why macros are offered in the first episode only (see armtransfer.learning.mapping)."""
    from armtransfer.tasks.catalog import TABLE_I

    coarse, fine = grid_robot("coarse"), grid_robot("fine")
    config = LearnerConfig()
    s1, g1 = TABLE_I[1].cells()
    t1 = trajectories.shortest(coarse, s1, g1)
    _, m = experiment.run_mapping(fine, s1, g1, t1, ActionMapping.for_robots(coarse, fine), 10, 0, config)
    s2, g2 = TABLE_I[2].cells()
    t2 = trajectories.shortest(coarse, s2, g2)
    shaping = methods.build_shaping("mapping", fine, t2, "auto", config.step_reward)
    start = fine.start_state(s2)
    first = MacroTable(m, t2, fine)
    every = MacroTable(m, t2, fine, episodes=None)
    conv_first = conv_every = 0
    for trial in range(10):
        rng = experiment.trial_rng(0, trial)
        conv_first += sarsa.learn(fine, start, g2, config, rng, shaping=shaping, macros=first).converged
        rng = experiment.trial_rng(0, trial)
        conv_every += sarsa.learn(fine, start, g2, config, rng, shaping=shaping, macros=every).converged
    assert conv_first == 10
    assert conv_every == 0


class _Macros:
    """A macro table by hand: at state 0, the sequence of actions ``seq``."""

    episodes = None

    def __init__(self, n_states: int, seq: list[int]):
        self.start = np.zeros(n_states, np.int64)
        self.length = np.zeros(n_states, np.int64)
        self.length[0] = len(seq)
        self.actions = np.array(seq, np.int64)

    def arrays(self, robot):
        return self.start, self.length, self.actions


@pytest.mark.parametrize("wind", [0.0, 1.0])
def test_a_macro_is_abandoned_on_what_the_robot_observes_after_wind(wind):
    """Action 0 runs into a wall at every state; the wind pushes one state on. Under wind 1
    the robot always moves, so it never observes a blocked step and the whole macro runs;
    without wind the macro is abandoned at its first, blocked step. Kernel and dense
    reference agree bit for bit."""
    from armtransfer.tasks.robot import DiscreteRobot

    n = 6
    nxt = np.array([[s, min(s + 1, n - 1)] for s in range(n)], np.int32)
    robot = DiscreteRobot("wall-and-wind", nxt, np.minimum(np.arange(n) + 1, n - 1).astype(np.int32),
                          np.arange(n, dtype=np.int32), ("W", "R"))
    macros = _Macros(n, [0, 0, 0])
    config = LearnerConfig(trace_cutoff=0.0, max_episodes=1, patience=1000, epsilon=0.0)
    rng_seed = 4
    fast = sarsa.learn(robot, 0, n - 1, config, np.random.default_rng(rng_seed), wind=wind,
                       macros=macros, keep_q=True)
    Q, steps = reference.learn(robot, 0, n - 1, config, np.random.default_rng(rng_seed), episodes=1,
                               wind=wind, macros=macros)
    assert fast.episode_steps.tolist() == steps
    assert np.array_equal(fast.Q, Q)
    assert fast.macro_steps[0] == (3 if wind == 1.0 else 1)


def test_a_mapping_is_refused_on_a_task_it_was_learned_on(tmp_path, capsys):
    path = tmp_path / "m.json"
    assert main(["rooms", "--method", "mapping", "--mapping", str(path), "--trials", "2", "--no-controls",
                 "--task", "1"]) == 0
    assert json.loads(path.read_text())["tasks"] == [list(table_task(1).cells())]
    capsys.readouterr()
    before = path.read_bytes()
    assert main(["rooms", "--method", "mapping", "--mapping", str(path), "--trials", "1", "--task", "1"]) == 2
    err = capsys.readouterr().err
    assert "the mapping was learned on this task, (0, 0) -> (-8, 12)" in err and len(err.strip().splitlines()) == 1
    assert path.read_bytes() == before
    assert main(["rooms", "--method", "mapping", "--mapping", str(path), "--trials", "1", "--no-controls",
                 "--task", "2"]) == 0
    assert json.loads(path.read_text())["tasks"] == [list(table_task(t).cells()) for t in (1, 2)]

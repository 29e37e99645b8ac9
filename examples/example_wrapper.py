"""Your own learner with the paper's transfer: a tabular agent on ArmRooms-v0, with and without
armtransfer.wrappers.TransferReward.

The agent below is plain epsilon-greedy Q-learning written here, knowing nothing of
armtransfer. Robot 1 (the source arm) hands over its shortest path as a trajectory of
(cell, action index); robot 2 (the env's arm) has other actions. The wrapper turns the
trajectory into extra reward, and the script prints how many steps robot 2 needs to first
reach the goal, with and without it, over several seeds.

    python examples/example_wrapper.py                 # planar2:joint learns from ur5e_like:cartesian
    python examples/example_wrapper.py --method dense --seeds 10
    python examples/example_wrapper.py --fast          # a few seconds: the smoke test runs this
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import gymnasium as gym  # noqa: E402
import numpy as np  # noqa: E402

import armtransfer  # noqa: E402
from armtransfer import script  # noqa: E402
from armtransfer.learning import trajectory as trajectories  # noqa: E402
from armtransfer.tasks.arms import arm_robot  # noqa: E402
from armtransfer.tasks.catalog import table_task  # noqa: E402
from armtransfer.wrappers import TransferReward  # noqa: E402

p = script.parser(__doc__)
p.add_argument("--arm", default="planar2", help="the learning arm (default planar2)")
p.add_argument("--actions", default="joint", help="its action model (default joint)")
p.add_argument("--source", default="ur5e_like:cartesian", help="the arm that hands over its path")
p.add_argument("--task", type=int, default=1, help="Table I task (default 1)")
p.add_argument("--method", default="dense", help="the transfer method (default dense; the paper's is pseudo)")
p.add_argument("--seeds", type=int, default=5, help="seeds per variant (default 5)")
p.add_argument("--episodes", type=int, default=30, help="episodes per run (default 30)")
p.add_argument("--fast", action="store_true", help="1 seed, 2 episodes")
args = p.parse_args()
if args.fast:
    args.seeds, args.episodes = 1, 2

# 1. The environment: robot 2, an arm on the rooms table.


def make_env(transfer: bool) -> gym.Env:
    env = gym.make("armtransfer/ArmRooms-v0", arm=args.arm, actions=args.actions, task=args.task,
                   max_episode_steps=500_000)
    if transfer:
        env = TransferReward(env, trajectory, method=args.method, gamma=0.99)
    return env


# 2. Robot 1's knowledge: its shortest path, as (cell, action index) pairs.
source_arm, _, source_actions = args.source.partition(":")
source = arm_robot(source_arm, source_actions or "cartesian")
start_cell, goal_cell = table_task(args.task).cells()
trajectory = trajectories.shortest(source, start_cell, goal_cell)
print(f"{source.name} hands over {len(trajectory)} (cell, action) pairs for task {args.task}")


# 3. A tabular learner written here: epsilon-greedy Q-learning, Q = 0 at the start.
def first_exposure(env: gym.Env, seed: int) -> list[int]:
    """Steps of each episode (the first is the exploration before the goal is first reached)."""
    rng = np.random.default_rng(seed)
    Q = np.zeros((env.observation_space.n, env.action_space.n))
    alpha, gamma, epsilon = 0.1, 0.99, 0.1
    lengths = []
    for episode in range(args.episodes):
        s, _ = env.reset(seed=seed + episode)
        steps, done = 0, False
        while not done:
            if rng.random() < epsilon:
                a = int(rng.integers(env.action_space.n))
            else:
                best = np.flatnonzero(Q[s] == Q[s].max())
                a = int(rng.choice(best))
            s2, r, terminated, truncated, _ = env.step(a)
            target = r if terminated else r + gamma * Q[s2].max()
            Q[s, a] += alpha * (target - Q[s, a])
            s, steps, done = s2, steps + 1, terminated or truncated
        lengths.append(steps)
    return lengths


# 4. The comparison.
results = {}
for transfer in (False, True):
    env = make_env(transfer)
    runs = [first_exposure(env, seed) for seed in range(args.seeds)]
    env.close()
    results[transfer] = runs
    first = [r[0] for r in runs]
    last = [r[-1] for r in runs]
    label = f"with {args.method}" if transfer else "without transfer"
    print(f"{label:>18}: first goal after {np.mean(first):,.0f} steps (mean of {args.seeds}); "
          f"episode {args.episodes}: {np.mean(last):,.0f} steps")

without = np.mean([r[0] for r in results[False]])
with_ = np.mean([r[0] for r in results[True]])
print(f"difference: {without - with_:,.0f} fewer steps to the first goal with transfer "
      f"({100 * (1 - with_ / without):.0f}%)")

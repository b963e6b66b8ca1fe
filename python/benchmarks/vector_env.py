"""How much faster the native vectorised environment steps than
Gymnasium's SyncVectorEnv over the same single environments, on the same
host, in one run.

    python benchmarks/vector_env.py [--envs 64] [--steps 2000] [--rounds 5] [--task 1]

Both step `--envs` environments of the task with the same random actions
(autoresets included) for `--steps` steps a round; the two are timed in
alternation, round by round, so that a shared host's noise hits them
alike, and the ratio of their median environment steps per second is
printed.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

import gymnasium
import numpy as np

import psa_esp  # noqa: F401 - registers the environments
from psa_esp.env import PsaEnv


def steps_per_second(env, actions):
    env.reset(seed=1)
    start = time.perf_counter()
    for action in actions:
        env.step(action)
    return len(actions) * len(actions[0]) / (time.perf_counter() - start)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--envs", type=int, default=64)
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--task", type=int, default=1)
    args = parser.parse_args()
    native = gymnasium.make_vec(f"psa_esp/Task{args.task}-v0", num_envs=args.envs, vectorization_mode="vector_entry_point")
    sync = gymnasium.vector.SyncVectorEnv([lambda: PsaEnv(args.task) for _ in range(args.envs)])
    actions = np.random.default_rng(1).uniform(0, 1, size=(args.steps, args.envs, 4))
    rates = {"native": [], "sync": []}
    for _ in range(args.rounds):
        rates["native"].append(steps_per_second(native, actions))
        rates["sync"].append(steps_per_second(sync, actions))
    medians = {name: statistics.median(values) for name, values in rates.items()}
    print(
        json.dumps(
            {
                "envs": args.envs,
                "steps": args.steps,
                "rounds": args.rounds,
                "native_steps_per_second": round(medians["native"]),
                "sync_steps_per_second": round(medians["sync"]),
                "ratio": round(medians["native"] / medians["sync"], 2),
            }
        )
    )


if __name__ == "__main__":
    main()

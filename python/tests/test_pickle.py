"""Pickling through the saved form: Run, Network, Asked, Ticket and the
environments survive pickle and copy.deepcopy, and a multiprocessing
pool evaluates bit for bit what one process does."""

from __future__ import annotations

import copy
import multiprocessing
import pickle

import gymnasium
import numpy as np

import psa_esp
from psa_esp.env import PsaEnv


def test_a_run_pickled_mid_generation_ends_as_the_original():
    run = psa_esp.Run(seed=6, generations=3)
    asked = run.ask()
    run.tell(asked.ticket, run.evaluate_psa(asked, 1))
    for clone in [pickle.loads(pickle.dumps(run)), copy.deepcopy(run)]:
        assert clone.to_json() == run.to_json()
    clone = pickle.loads(pickle.dumps(run))
    mine, theirs = run.run_psa(1), clone.run_psa(1)
    assert mine["champion"]["fitness"] == theirs["champion"]["fitness"]
    assert np.array_equal(mine["champion"]["weights"], theirs["champion"]["weights"])
    assert mine["records"] == theirs["records"]


def test_networks_and_asks_pickle_through_their_saved_form(champions):
    network = psa_esp.Network(champions[1], 1)
    for clone in [pickle.loads(pickle.dumps(network)), copy.deepcopy(network)]:
        assert clone.to_json() == network.to_json()
    run = psa_esp.Run(seed=8, generations=2)
    asked = run.ask()
    for clone in [pickle.loads(pickle.dumps(asked)), copy.deepcopy(asked)]:
        assert np.array_equal(clone.weights, asked.weights)
        assert np.array_equal(clone.lesioned, asked.lesioned)
        assert (clone.seed, clone.key, clone.purpose, clone.generation) == (asked.seed, asked.key, asked.purpose, asked.generation)
        assert np.array_equal(run.evaluate_psa(clone, 1), run.evaluate_psa(asked, 1))
    ticket = pickle.loads(pickle.dumps(asked.ticket))
    run.tell(ticket, run.evaluate_psa(asked, 1))


def test_environments_pickle_mid_episode_and_fly_on_as_the_original():
    env = gymnasium.make("psa_esp/Task2-v0", config={"problem": {"noise": {"output_sd": 0.05}}})
    env.reset(seed=3)
    for _ in range(10):
        env.step(np.full(4, 0.3))
    clones = [pickle.loads(pickle.dumps(env)), copy.deepcopy(env)]
    for step in range(30):
        action = np.full(4, 0.2 + step / 100)
        mine = env.step(action)
        for clone in clones:
            theirs = clone.step(action)
            assert mine[0].tobytes() == theirs[0].tobytes()
            assert mine[1:4] == theirs[1:4] and mine[4] == theirs[4]
    fresh = pickle.loads(pickle.dumps(PsaEnv(1)))
    assert fresh.reset(seed=1)[0].tobytes() == PsaEnv(1).reset(seed=1)[0].tobytes()


def _score(weights):
    return psa_esp.evaluate(weights, 1, seed=9, trials=2, threads=1)


def test_a_multiprocessing_pool_evaluates_bit_for_bit_as_serial():
    run = psa_esp.Run(seed=12, generations=2)
    asked = run.ask()
    serial = np.concatenate([_score(asked.weights[i : i + 5]) for i in range(0, len(asked), 5)])
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        parallel = np.concatenate(pool.map(_score, [asked.weights[i : i + 5] for i in range(0, len(asked), 5)]))
        runs = pool.map(pickle.dumps, [run])
    assert serial.tobytes() == parallel.tobytes()
    assert pickle.loads(runs[0]).to_json() == run.to_json()

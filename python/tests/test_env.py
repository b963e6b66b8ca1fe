"""The Gymnasium environments: check_env, and a trial flown step by step
scoring what evaluate gives."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import psa_esp
from psa_esp.env import PsaEnv


@pytest.mark.parametrize("task", [1, 2, 3])
def test_check_env_passes(task):
    env = gymnasium.make(f"psa_esp/Task{task}-v0")
    check_env(env.unwrapped, skip_render_check=True)
    check_env(PsaEnv(task, {"problem": {"noise": {"input_sd": 0.05, "output_sd": 0.05}}}), skip_render_check=True)


def fly(env, network, seed):
    """One episode of `network` from reset(seed); the rewards and the last info."""
    observation, info = env.reset(seed=seed)
    rewards = []
    while True:
        observation, reward, terminated, truncated, info = env.step(network.activate(observation))
        rewards.append(reward)
        assert not terminated
        if truncated:
            return rewards, info


@pytest.mark.parametrize(
    ("task", "problem"),
    [
        (1, {}),
        (2, {"noise": {"input_sd": 0.05, "output_sd": 0.05}}),
        (3, {"random_init": True, "noise": {"input_sd": 0.05}}),
        (1, {"random_init": True, "fitness": {"kind": "original"}}),
    ],
)
def test_a_trial_flown_step_by_step_scores_what_evaluate_gives(champions, task, problem):
    config = {"problem": problem}
    network = psa_esp.Network(champions[task], task, config)
    env = gymnasium.make(f"psa_esp/Task{task}-v0", config=config)
    for seed in [1, 42]:
        rewards, info = fly(env, network, seed)
        expected = psa_esp.evaluate(champions[task][None], task, config, seed=seed, trials=1)[0]
        assert info["fitness"] == expected
        assert len(rewards) == env.unwrapped.steps == 500
        assert sum(rewards) == pytest.approx(expected, abs=1e-9)
    assert expected > 0


@pytest.mark.parametrize("steps", [800, 120])
def test_an_episode_lasts_the_configured_steps_made_through_gymnasium(steps):
    # Longer and shorter trials than the default 500: the episode ends with
    # the trial, whatever the registration or gymnasium's wrappers.
    env = gymnasium.make("psa_esp/Task1-v0", config={"problem": {"steps": steps}})
    env.reset(seed=1)
    flown = 0
    while True:
        _, _, terminated, truncated, _ = env.step(np.zeros(4))
        flown += 1
        assert not terminated
        if truncated:
            break
    assert flown == steps == env.unwrapped.steps


def test_reset_by_seed_is_deterministic_and_random_starts_differ():
    env = PsaEnv(1, random_init=True)
    first, info = env.reset(seed=3)
    again, _ = env.reset(seed=3)
    assert np.array_equal(first, again)
    other, _ = env.reset(seed=4)
    assert not np.array_equal(first, other), "a random start's heading depends on the seed"
    paper = PsaEnv(1)
    assert np.array_equal(paper.reset(seed=3)[0], paper.reset(seed=4)[0]), "the paper's start is fixed"


def test_stepping_wrongly_raises_clear_exceptions():
    env = PsaEnv(2)
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros(4))
    env.reset(seed=1)
    with pytest.raises(ValueError, match="finite"):
        env.step(np.array([0.0, np.nan, 0.0, 0.0]))
    with pytest.raises(ValueError):
        env.step(np.zeros(3))
    for _ in range(env.steps):
        env.step(np.zeros(4))
    with pytest.raises(RuntimeError, match="over"):
        env.step(np.zeros(4))
    with pytest.raises(psa_esp.ConfigError, match="no_such"):
        PsaEnv(1, {"problem": {"no_such": 1}})
    with pytest.raises(psa_esp.ConfigError, match="random-initialisation"):
        PsaEnv(2, random_init=True)


@pytest.mark.parametrize("backend", ["native", "ode"])
def test_an_environment_steps_on_its_own_thread_and_another_thread_gets_a_runtime_error(backend):
    import threading

    def in_thread(work):
        """`work()` on a new thread: its result, or the exception it raised."""
        outcome = {}

        def target():
            try:
                outcome["value"] = work()
            except BaseException as error:  # noqa: BLE001 - the test reads the class
                outcome["error"] = error

        thread = threading.Thread(target=target)
        thread.start()
        thread.join()
        return outcome

    env = PsaEnv(1, {"problem": {"backend": backend}})
    env.reset(seed=3)
    thrust = np.full(4, 0.5)
    moved = in_thread(lambda: env.step(thrust))
    # An Exception (not pyo3's PanicException, a BaseException) naming the rule.
    assert isinstance(moved.get("error"), RuntimeError), moved
    assert "thread that made it" in str(moved["error"])
    moved = in_thread(lambda: env.reset(seed=3))
    assert isinstance(moved.get("error"), RuntimeError), moved
    # Still usable on its own thread, and its attributes read anywhere.
    assert len(env.step(thrust)) == 5
    assert in_thread(lambda: env.unwrapped._trial.steps_done) == {"value": 1}

    # One made in each thread steps there, with the main thread's bits.
    def episode():
        own = PsaEnv(1, {"problem": {"backend": backend}})
        own.reset(seed=3)
        return [own.step(thrust)[1] for _ in range(20)]

    here = episode()
    there = in_thread(episode)
    assert there == {"value": here}


@pytest.mark.parametrize(
    ("task", "problem"),
    [(1, {"steps": 40}), (3, {"steps": 30, "random_init": True, "noise": {"input_sd": 0.05, "output_sd": 0.05}})],
)
def test_the_native_vector_env_flies_what_sync_vector_env_flies_bit_for_bit(task, problem):
    config = {"problem": problem}
    native = gymnasium.make_vec(
        f"psa_esp/Task{task}-v0", num_envs=5, vectorization_mode="vector_entry_point", config=config
    )
    sync = gymnasium.vector.SyncVectorEnv([lambda: PsaEnv(task, config) for _ in range(5)])
    assert native.single_observation_space == sync.single_observation_space
    rng = np.random.default_rng(task)
    for first in (11, None):
        if first is None:
            # Unseeded resets draw each trial's seed from the sub-environment's generator.
            native.unwrapped._generators = [np.random.default_rng(100 + i) for i in range(5)]
            for i, env in enumerate(sync.envs):
                env._np_random = np.random.default_rng(100 + i)
        mine, info = native.reset(seed=first)
        theirs, their_info = sync.reset(seed=first)
        assert np.array_equal(mine, theirs)
        assert np.array_equal(info["trial_seed"], their_info["trial_seed"])
        # Past two trial lengths: the autoreset on the next step included.
        for _ in range(95):
            actions = rng.uniform(-0.2, 1.2, size=(5, 4))
            got = native.step(actions)
            want = sync.step(actions)
            for a, b in zip(got[:4], want[:4]):
                assert np.array_equal(a, b)
            assert np.array_equal(got[4]["fitness"], want[4]["fitness"])

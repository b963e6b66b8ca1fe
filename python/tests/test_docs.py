"""The package's documentation and the environment's spec: what a new
user needs to install it, to avoid importing the source folder, and to
read observations, actions, info and episode length."""

from __future__ import annotations

import re

import gymnasium
import numpy as np

import psa_esp
from psa_esp.env import PsaEnv

from conftest import REPO

README = (REPO / "python" / "README.md").read_text()


def test_readme_explains_the_venv_and_the_source_folder_trap():
    assert "externally-managed-environment" in README
    assert "python3 -m venv" in README
    assert "ModuleNotFoundError: No module named 'psa_esp._native'" in README


def test_readme_snippets_name_what_they_use():
    assert not re.search(r"evaluate\(weights\[None\]", README)
    assert "network.weights[None]" in README


def test_readme_documents_observation_action_and_state_order():
    for words in ["info[\"state\"]", "vx", "omega", "thruster"]:
        assert words in README, words


def test_the_environment_gives_the_episode_length_and_the_space_its_bounds():
    for task in psa_esp.TASKS:
        env = gymnasium.make(f"psa_esp/Task{task}-v0")
        # The environment truncates its episodes itself: no TimeLimit.
        assert env.spec.max_episode_steps is None
        assert env.unwrapped.steps == 500
    space = PsaEnv(1).observation_space
    assert space.low[6] == space.high[6] == 1.0, "the bias is 1"
    assert np.isfinite(space.low[4]) and np.isfinite(space.high[4]), "the heading input is wrapped"
    assert not np.isfinite(space.low[0])
    noisy = PsaEnv(1, {"problem": {"noise": {"input_sd": 0.1, "on_bias": True}}}).observation_space
    assert not np.isfinite(noisy.high[6]) and not np.isfinite(noisy.high[4])
    env = PsaEnv(1)
    observation, _ = env.reset(seed=1)
    for _ in range(200):
        observation, *_ = env.step(np.array([1.0, 0.0, 0.0, 1.0]))
        assert env.observation_space.contains(observation)

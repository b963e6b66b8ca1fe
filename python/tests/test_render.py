"""rgb_array rendering: frames drawn by the drawing code of replay's
pictures, one (H, W, 3) uint8 array a step, that change as the robot
moves."""

from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium.utils.env_checker import check_env

import psa_esp  # noqa: F401
from psa_esp.env import PsaEnv


def test_rgb_array_frames_have_their_shape_and_follow_the_robot():
    env = gymnasium.make("psa_esp/Task1-v0", render_mode="rgb_array")
    assert env.metadata["render_fps"] == 20
    env.reset(seed=1)
    first = env.render()
    assert first.dtype == np.uint8 and first.ndim == 3 and first.shape[2] == 3
    assert first.shape[0] >= 200 and first.shape[1] >= 200
    assert len(np.unique(first.reshape(-1, 3), axis=0)) > 2, "a frame draws something"
    frames = [first]
    for _ in range(40):
        env.step(np.array([1.0, 0.0, 0.0, 1.0]))
        frames.append(env.render())
    assert all(f.shape == first.shape for f in frames)
    assert not np.array_equal(frames[0], frames[-1]), "the robot moved"
    assert not np.array_equal(frames[-2], frames[-1])


def test_render_checks_pass_and_other_modes_are_refused():
    check_env(PsaEnv(2, render_mode="rgb_array"))
    try:
        PsaEnv(1, render_mode="human")
    except ValueError as error:
        assert "rgb_array" in str(error)
    else:
        raise AssertionError("render_mode='human' was accepted")
    assert PsaEnv(1).render() is None

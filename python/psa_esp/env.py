"""The PSA as a Gymnasium environment, one per task.

``gymnasium.make("psa_esp/Task1-v0")`` (after ``import psa_esp``), or
``PsaEnv(task, config=...)``:

- the observation is the network's 7 inputs (position x and y relative
  to the target, velocity, heading error, spin, bias), scaled as the model
  scales them, with input noise where configured;
- the action is the four thrusters' commands, each clamped to [0, 1] after
  the output noise, if any;
- the reward is the step's increment of the evolution fitness, in % of
  the task's theoretical maximum, so that an episode's rewards add up to
  the trial's fitness (``info["fitness"]`` holds it exactly: after the
  last step, the bits :func:`psa_esp.evaluate` gives for one trial);
- an episode is one trial: truncated after its steps (500 by default);
- ``reset(seed=S)`` starts the trial as ``psa-esp replay --seed S`` starts
  its first: the paper's start, or a random one when the configuration
  (or ``random_init=True``) asks for it.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from ._native import INPUTS, OUTPUTS, Trial


class PsaEnv(gymnasium.Env):
    """One task of the PSA; see the module's documentation."""

    metadata: dict[str, Any] = {"render_modes": []}

    def __init__(self, task=1, config=None, *, preset="baseline", backend=None, random_init=None, render_mode=None):
        if render_mode is not None:
            raise ValueError(f"PsaEnv renders nothing (render_mode must be None, got {render_mode!r})")
        self.task = task
        self._trial = Trial(task, config, preset=preset, backend=backend, random_init=random_init)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(INPUTS,), dtype=np.float64)
        self.action_space = spaces.Box(0.0, 1.0, shape=(OUTPUTS,), dtype=np.float64)
        self.render_mode = None

    @property
    def steps(self) -> int:
        """Steps an episode lasts."""
        return self._trial.steps

    def reset(self, *, seed=None, options=None):
        """Starts a trial. With ``seed``, the trial ``replay --seed seed``
        flies first; without, one drawn from the environment's generator."""
        super().reset(seed=seed)
        trial_seed = int(seed) if seed is not None else int(self.np_random.integers(0, 2**63))
        observation = self._trial.reset(trial_seed)
        return observation, {"fitness": 0.0, "trial_seed": trial_seed, "state": self._trial.state}

    def step(self, action):
        """One control step: the thrusters' commands for 0.05 s."""
        observation, reward = self._trial.step(np.asarray(action, dtype=np.float64).reshape(OUTPUTS))
        truncated = self._trial.done
        info = {"fitness": self._trial.fitness, "state": self._trial.state}
        return observation, reward, False, truncated, info

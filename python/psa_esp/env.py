"""The PSA as a Gymnasium environment, one per task.

``gymnasium.make("psa_esp/Task1-v0")`` (after ``import psa_esp``), or
``PsaEnv(task, config=...)``:

- the observation is the network's 7 inputs, in this order: x and y of
  the position relative to the target, vx and vy (the velocity), the
  heading input (the heading by default, or its error from the target;
  wrapped), omega (the spin) and the bias, each scaled as the model
  scales it, with input noise where configured; the observation space
  bounds the heading input and the bias where no noise reaches them;
- the action is the four thrusters' commands (thrusters 0 to 3), each
  clamped to [0, 1] after the output noise, if any;
- the reward is the step's increment of the evolution fitness, in % of
  the task's theoretical maximum, so that an episode's rewards add up to
  the trial's fitness (``info["fitness"]`` holds it exactly: after the
  last step, the bits :func:`psa_esp.evaluate` gives for one trial);
  ``info["state"]`` is the body's true state: x, y (m), heading (rad),
  vx, vy (m/s), omega (rad/s);
- an episode is one trial: the environment truncates it after the
  configuration's ``problem.steps`` (500 by default) itself, whatever
  wraps it (the registered environments carry no ``TimeLimit``);
- ``reset(seed=S)`` starts the trial as ``psa-esp replay --seed S`` starts
  its first: the paper's start, or a random one when the configuration
  (or ``random_init=True``) asks for it;
- ``render_mode="rgb_array"``: ``render()`` draws the trial so far as
  ``psa-esp replay`` draws its picture, an (H, W, 3) uint8 array;
- it pickles (and copies) mid-episode: the copy flies on as the original.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ._native import INPUTS, OUTPUTS, Trial, TrialBatch



class PsaEnv(gymnasium.Env):
    """One task of the PSA; see the module's documentation."""

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 20}

    def __init__(self, task=1, config=None, *, preset="baseline", backend=None, random_init=None, render_mode=None):
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"PsaEnv renders only 'rgb_array' frames (render_mode None or 'rgb_array', got {render_mode!r})")
        self.task = task
        self._arguments = {"task": task, "config": config, "preset": preset, "backend": backend, "random_init": random_init}
        self._trial = Trial(task, config, preset=preset, backend=backend, random_init=random_init)
        low, high = self._trial.observation_bounds
        self.observation_space = spaces.Box(np.array(low), np.array(high), shape=(INPUTS,), dtype=np.float64)
        self.action_space = spaces.Box(0.0, 1.0, shape=(OUTPUTS,), dtype=np.float64)
        self.render_mode = render_mode
        self.metadata = {**PsaEnv.metadata, "render_fps": 1.0 / self._trial.dt}
        self._trial_seed = None
        self._actions = []

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
        self._trial_seed, self._actions = trial_seed, []
        return observation, {"fitness": 0.0, "trial_seed": trial_seed, "state": self._trial.state}

    def step(self, action):
        """One control step: the thrusters' commands for 0.05 s."""
        action = np.array(action, dtype=np.float64).reshape(OUTPUTS)
        observation, reward = self._trial.step(action)
        self._actions.append(action)
        truncated = self._trial.done
        info = {"fitness": self._trial.fitness, "state": self._trial.state}
        return observation, reward, False, truncated, info

    def __repr__(self):
        arguments = ", ".join(f"{key}={value!r}" for key, value in self._arguments.items() if value is not None and key != "task")
        return f"PsaEnv(task={self.task!r}{', ' + arguments if arguments else ''}; {self._trial!r})"

    def render(self):
        """The trial so far as an (H, W, 3) uint8 array under
        ``render_mode="rgb_array"``; None without a render mode."""
        if self.render_mode is None:
            return None
        return self._trial.frame()

    def __getstate__(self):
        # The saved form: the arguments, the trial's seed and the actions
        # applied since; the trial itself (a physics world) is flown again.
        state = self.__dict__.copy()
        del state["_trial"]
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        arguments = dict(self._arguments)
        self._trial = Trial(arguments.pop("task"), arguments.pop("config"), **arguments)
        if self._trial_seed is not None:
            self._trial.reset(self._trial_seed)
            for action in self._actions:
                self._trial.step(action)


class PsaVectorEnv(VectorEnv):
    """``num_envs`` environments of one task stepped in one native call:
    ``gymnasium.make_vec("psa_esp/Task1-v0", num_envs=64,
    vectorization_mode="vector_entry_point")``. Each sub-environment flies
    exactly what a :class:`PsaEnv` with the same arguments flies inside a
    ``SyncVectorEnv`` (the same seeds, the same autoreset on the next step):
    the same observations, rewards and endings, bit for bit."""

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, num_envs=1, task=1, config=None, *, preset="baseline", backend=None, random_init=None):
        self.num_envs = num_envs
        self._batch = TrialBatch(num_envs, task, config, preset=preset, backend=backend, random_init=random_init)
        single = PsaEnv(task, config, preset=preset, backend=backend, random_init=random_init)
        self.single_observation_space = single.observation_space
        self.single_action_space = single.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.metadata = {**PsaVectorEnv.metadata, "render_fps": single.metadata["render_fps"]}
        self._generators = [None] * num_envs
        self._trial_seeds = np.zeros(num_envs, dtype=np.uint64)
        self._autoreset = np.zeros(num_envs, dtype=np.bool_)
        self._observations = np.zeros((num_envs, INPUTS))

    def _start(self, index, seed):
        # As PsaEnv.reset: a given seed is the trial's; without one, the
        # sub-environment's own generator draws it.
        if seed is not None:
            self._generators[index], _ = seeding.np_random(seed)
            trial_seed = int(seed)
        else:
            if self._generators[index] is None:
                self._generators[index], _ = seeding.np_random()
            trial_seed = int(self._generators[index].integers(0, 2**63))
        self._trial_seeds[index] = trial_seed
        self._observations[index] = self._batch.reset(index, trial_seed)

    def reset(self, *, seed=None, options=None):
        """Starts every trial (or those of ``options["reset_mask"]``): an
        int ``seed`` gives sub-environment i the seed ``seed + i``."""
        super().reset(seed=seed)
        if seed is None:
            seeds = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
        if len(seeds) != self.num_envs:
            raise ValueError(f"seed must be an int or {self.num_envs} seeds, got {len(seeds)}")
        mask = np.ones(self.num_envs, dtype=np.bool_)
        if options is not None and "reset_mask" in options:
            mask = np.asarray(options["reset_mask"], dtype=np.bool_).reshape(self.num_envs)
        for i in np.flatnonzero(mask):
            self._start(i, seeds[i])
        self._autoreset[mask] = False
        info = {"fitness": self._batch.fitness, "trial_seed": self._trial_seeds.copy(), "state": self._batch.states}
        return self._observations.copy(), info

    def step(self, actions):
        """One control step of every trial; a trial that ended on the last
        step is started again instead (from its generator's next seed)."""
        actions = np.asarray(actions, dtype=np.float64).reshape(self.num_envs, OUTPUTS)
        restarted = self._autoreset.copy()
        for i in np.flatnonzero(restarted):
            self._start(i, None)
        observations, rewards, truncated = self._batch.step(actions, restarted)
        self._observations = observations
        self._autoreset = truncated.copy()
        terminated = np.zeros(self.num_envs, dtype=np.bool_)
        info = {"fitness": self._batch.fitness, "state": self._batch.states}
        return observations.copy(), rewards, terminated, truncated, info

    def __repr__(self):
        return f"PsaVectorEnv(num_envs={self.num_envs}, {self._batch!r})"

"""psa_esp: the Personal Satellite Assistant and ESP from Python.

A thin binding of psa-esp's Rust crates (the simulator ``psa-sim`` and the
search crate ``esp-neuroevolution``), giving the same bits as the
``psa-esp`` command line for the same network, configuration and seed:

- :func:`evaluate` scores a NumPy array of networks on a task, batched on
  the crate's threads with the GIL released;
- ``gymnasium.make("psa_esp/Task1-v0")`` (and ``Task2``, ``Task3``) fly
  the robot a step at a time;
- :class:`Run` drives ESP or the hill-climber by ask and tell, on the PSA
  natively (:meth:`Run.run_psa`, what ``psa-esp evolve`` does) or on a
  fitness function of your own (:meth:`Run.optimize`), and saves and
  resumes through the crate's serde;
- :class:`Network`, :func:`load_network` and :func:`replay` read, write
  and fly network files in the CLI's format;
- :func:`welch` is the report's Welch t-test, for comparisons of your own.

A network's weights are laid out as in a network file: hidden neuron
after hidden neuron, each its 7 input weights (bias last), then its 4
output weights; an array of networks is (networks, hidden, 11) or
(networks, hidden * 11). Fitness is in % of the task's theoretical
maximum. The package's configurations start from the paper's baseline on
the ``native`` backend (bit-identical to ``ode``, many times faster).
"""

from __future__ import annotations

from pathlib import Path as _Path

import gymnasium

from . import _native, errors
from ._native import (
    GENES_PER_NEURON,
    INPUTS,
    OUTPUTS,
    Asked,
    Network,
    Run,
    Ticket,
    Trial,
    TrialBatch,
    __version__,
    build,
    evaluate,
    load_network,
    replay,
    resolve_config,
    welch,
)
from .errors import *  # noqa: F401,F403

TASKS = (1, 2, 3)

# The portable wheel carries DejaVu Sans (python/build-wheel puts it here):
# rendering then needs no font on the machine and draws the same text on
# every one. A plain install has no copy and uses the system's.
_PACKAGED_FONT = _Path(__file__).with_name("fonts") / "DejaVuSans.ttf"
if _PACKAGED_FONT.is_file():
    _native._use_packaged_font(str(_PACKAGED_FONT))


def evolve(
    task,
    preset="baseline",
    config=None,
    *,
    seed=1,
    generations=None,
    backend=None,
    eval_path="fastest",
    threads=None,
    callback=None,
    out=None,
):
    """One evolution run of ``preset`` on ``task``: what ``psa-esp evolve
    --task T --preset P --seed S [--config F] [--generations G]
    [--backend B]`` runs, bit for bit (the package's default backend is
    ``native``; the CLI's is ``ode``, which gives the same bits).

    ``callback(record)`` is called after each generation (cycle) with its
    record (the columns of ``records.csv``); returning True stops the run.
    With ``out`` it writes the run folder ``evolve --out`` writes.
    ``seed=None`` draws a fresh seed. Returns the result: ``champion``,
    ``records``, ``ending`` and ``seed`` (the seed used).
    """
    run = Run(seed=seed, config=config, preset=preset, backend=backend, generations=generations)
    result = run.run_psa(task, callback, eval_path=eval_path, threads=threads, out=out)
    result["seed"] = run.seed
    return result


for _task in TASKS:
    _id = f"psa_esp/Task{_task}-v0"
    if _id not in gymnasium.registry:
        gymnasium.register(
            id=_id,
            entry_point="psa_esp.env:PsaEnv",
            vector_entry_point="psa_esp.env:PsaVectorEnv",
            kwargs={"task": _task},
            # No TimeLimit: an episode ends with its trial, whose length
            # the configuration gives (`problem.steps`).
            max_episode_steps=None,
        )

__all__ = [
    "GENES_PER_NEURON",
    "INPUTS",
    "OUTPUTS",
    "TASKS",
    "Asked",
    "Network",
    "Run",
    "Ticket",
    "Trial",
    "TrialBatch",
    "__version__",
    "build",
    "errors",
    "evaluate",
    "evolve",
    "load_network",
    "replay",
    "resolve_config",
    *errors.__all__,
]

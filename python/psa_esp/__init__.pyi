from collections.abc import Callable
from os import PathLike
from typing import Any

from . import errors as errors
from ._native import (
    GENES_PER_NEURON as GENES_PER_NEURON,
    INPUTS as INPUTS,
    OUTPUTS as OUTPUTS,
    Asked as Asked,
    Config,
    Network as Network,
    Run as Run,
    Ticket as Ticket,
    Trial as Trial,
    TrialBatch as TrialBatch,
    __version__ as __version__,
    build as build,
    evaluate as evaluate,
    load_network as load_network,
    replay as replay,
    resolve_config as resolve_config,
    welch as welch,
)
from .errors import *

TASKS: tuple[int, int, int]

def evolve(
    task: int,
    preset: str = "baseline",
    config: Config = None,
    *,
    seed: int | None = 1,
    generations: int | None = None,
    backend: str | None = None,
    eval_path: str = "fastest",
    threads: int | None = None,
    callback: Callable[[dict[str, Any]], object] | None = None,
    out: str | PathLike[str] | None = None,
) -> dict[str, Any]:
    """One evolution run: what ``psa-esp evolve`` runs, bit for bit."""

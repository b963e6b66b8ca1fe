"""Type stubs of psa_esp._native, the PyO3 module under psa_esp."""

from collections.abc import Callable, Sequence
from os import PathLike
from typing import Any, Literal, Mapping, SupportsIndex

import numpy as np
import numpy.typing as npt

__version__: str
build: str
INPUTS: int
OUTPUTS: int
GENES_PER_NEURON: int

Config = Mapping[str, Any] | str | PathLike[str] | None
Weights = npt.NDArray[np.float64]
Record = dict[str, Any]
Result = dict[str, Any]

def evaluate(
    weights: Weights,
    task: int,
    config: Config = None,
    *,
    seed: SupportsIndex | Sequence[SupportsIndex] | npt.NDArray[np.integer[Any]] | None = 1,
    trials: SupportsIndex | None = None,
    lesioned: npt.NDArray[np.bool_] | None = None,
    preset: str = "baseline",
    backend: Literal["ode", "native", "rapier"] | None = None,
    eval_path: str = "fastest",
    threads: SupportsIndex | None = None,
    return_seed: bool = False,
) -> Any:
    """The fitness of every network in ``weights`` (networks, hidden, 11)
    or (networks, hidden * 11), float64 or float32, on ``task``, in % of
    the task's maximum: network j flown as ``psa-esp replay --seed
    seed[j]`` flies it, the same bits. ``seed=None`` draws a fresh seed;
    ``return_seed=True`` returns ``(fitness, seed)``. Batched on the
    crate's threads with the GIL released."""

def reference_evaluations_per_second(
    weights: Weights,
    task: int,
    *,
    rounds: int = 3,
    config: Config = None,
    preset: str = "baseline",
    eval_path: str = "fastest",
    threads: int | None = None,
) -> list[float]:
    """Networks per second of the crate's own batched evaluation (what
    ``psa-esp bench`` times), one rate per round: the benchmark's reference."""

def resolve_config(config: Config = None, *, preset: str = "baseline", backend: Literal["ode", "native", "rapier"] | None = None) -> str:
    """The whole configuration ``config`` resolves to, as TOML."""

class Ticket:
    """The receipt of an ask, which ``Run.tell`` takes back."""

class Asked:
    """The networks a run asks to have evaluated."""

    @property
    def ticket(self) -> Ticket: ...
    @property
    def weights(self) -> npt.NDArray[np.float64]:
        """(networks, hidden, genes); lesioned neurons' weights are zeros."""
    @property
    def lesioned(self) -> npt.NDArray[np.bool_]:
        """(networks, hidden)."""
    @property
    def purpose(self) -> Literal["generation", "lesion_test", "base"]: ...
    @property
    def generation(self) -> int | None: ...
    @property
    def seed(self) -> int: ...
    @property
    def key(self) -> list[int]: ...
    def __len__(self) -> int: ...

class Run:
    """A run of ESP or of the hill-climber, driven from Python."""

    def __init__(
        self,
        algorithm: Literal["esp", "hill_climb", "hill-climb"] | None = None,
        *,
        seed: SupportsIndex | None = 1,
        config: Config = None,
        preset: str = "baseline",
        backend: Literal["ode", "native", "rapier"] | None = None,
        inputs: SupportsIndex | None = None,
        outputs: SupportsIndex | None = None,
        generations: SupportsIndex | None = None,
        goal: float | None = None,
        max_evaluations: SupportsIndex | None = None,
    ) -> None: ...
    def ask(self) -> Asked | None:
        """The networks to evaluate next, or None once the run has ended."""
    def tell(self, ticket: Ticket, fitness: npt.ArrayLike) -> Record | None:
        """Advances the run by the asked networks' fitness; the record of
        the generation this completes, if any."""
    def stop(self) -> None:
        """Ends the run once its current generation is complete."""
    @property
    def ending(self) -> Literal["completed", "goal", "budget", "stopped"] | None: ...
    @property
    def records(self) -> list[Record]: ...
    @property
    def seed(self) -> int: ...
    @property
    def algorithm(self) -> Literal["esp", "hill_climb"]: ...
    @property
    def config(self) -> str:
        """The run's whole configuration as TOML."""
    def result(self) -> Result:
        """``champion``, ``records``, ``ending``; during the run the best
        so far (``ending`` None); NotEndedError before any network is told."""
    def evaluate_psa(
        self, asked: Asked, task: int, *, eval_path: str = "fastest", threads: int | None = None
    ) -> npt.NDArray[np.float64]:
        """The asked networks' fitness on ``task``, as ``psa-esp evolve`` gives it."""
    def run_psa(
        self,
        task: int,
        callback: Callable[[Record], object] | None = None,
        *,
        eval_path: str = "fastest",
        threads: int | None = None,
        out: str | PathLike[str] | None = None,
    ) -> Result:
        """Runs to the end on the PSA, natively: ``psa-esp evolve``'s run."""
    def optimize(
        self,
        fitness: Callable[[npt.NDArray[np.float64]], npt.ArrayLike],
        callback: Callable[[Record], object] | None = None,
    ) -> Result:
        """Runs to the end on a fitness function of your own."""
    def to_json(self) -> str:
        """The run saved: configuration, seed and whole state."""
    @staticmethod
    def from_json(text: str) -> Run:
        """A run saved by ``to_json``."""
    def save_champion(self, path: str | PathLike[str], task: int) -> None:
        """The ended run's champion as ``champion.json`` in the CLI's format."""

class Network:
    """A controller of the PSA with its network file."""

    def __init__(
        self,
        weights: Weights,
        task: int = 1,
        config: Config = None,
        *,
        lesioned: npt.NDArray[np.bool_] | None = None,
        provenance: Mapping[str, Any] | None = None,
        preset: str = "baseline",
        backend: Literal["ode", "native", "rapier"] | None = None,
    ) -> None: ...
    @property
    def weights(self) -> npt.NDArray[np.float64]:
        """(hidden, 11)."""
    @property
    def lesioned(self) -> npt.NDArray[np.bool_]: ...
    @property
    def hidden(self) -> int: ...
    @property
    def task(self) -> int: ...
    @property
    def problem(self) -> dict[str, Any]: ...
    @property
    def provenance(self) -> dict[str, Any]: ...
    def activate(self, inputs: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The four outputs for 7 inputs, as a trial computes them; (N, 4) for an (N, 7) batch."""
    def to_json(self) -> str: ...
    def save(self, path: str | PathLike[str]) -> None: ...

def load_network(path: str | PathLike[str]) -> Network:
    """Reads a network file (``champion.json``)."""

def replay(
    network: Network | str | PathLike[str],
    task: int | None = None,
    *,
    backend: Literal["ode", "native", "rapier"] = "ode",
    input_noise: float = 0.0,
    output_noise: float = 0.0,
    random_init: bool = False,
    trials: int = 1,
    seed: int = 1,
    config: Config = None,
    default_model: bool = False,
) -> dict[str, Any]:
    """Flies a network as ``psa-esp replay`` does; what ``replay --json`` prints."""

class Trial:
    """One trial of a task, flown a control step at a time, on the thread that made it."""

    inputs: int
    def __init__(
        self,
        task: int,
        config: Config = None,
        *,
        preset: str = "baseline",
        backend: Literal["ode", "native", "rapier"] | None = None,
        random_init: bool | None = None,
    ) -> None: ...
    def reset(self, seed: int) -> npt.NDArray[np.float64]: ...
    def step(self, thrust: npt.ArrayLike) -> tuple[npt.NDArray[np.float64], float]: ...
    @property
    def fitness(self) -> float: ...
    @property
    def steps_done(self) -> int: ...
    @property
    def steps(self) -> int: ...
    @property
    def done(self) -> bool: ...
    @property
    def state(self) -> list[float]: ...
    @property
    def target(self) -> list[float]: ...
    @property
    def dt(self) -> float: ...
    @property
    def observation_bounds(self) -> tuple[list[float], list[float]]: ...
    def frame(self) -> npt.NDArray[np.uint8]:
        """The trial so far drawn as ``psa-esp replay``'s picture, (H, W, 3)."""

class TrialBatch:
    """``count`` trials of one task stepped in one call (the native side of
    ``psa_esp.env.PsaVectorEnv``), on the thread that made it."""

    def __init__(
        self,
        count: int,
        task: int,
        config: Config = None,
        *,
        preset: str = "baseline",
        backend: Literal["ode", "native", "rapier"] | None = None,
        random_init: bool | None = None,
    ) -> None: ...
    def reset(self, index: int, seed: int) -> npt.NDArray[np.float64]: ...
    def step(
        self, thrust: npt.NDArray[np.float64], skip: npt.NDArray[np.bool_]
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.bool_]]: ...
    @property
    def fitness(self) -> npt.NDArray[np.float64]: ...
    @property
    def states(self) -> npt.NDArray[np.float64]: ...
    def __len__(self) -> int: ...

def welch(a: Sequence[float], b: Sequence[float]) -> tuple[float, float, float]:
    """Welch's two-sample, two-tailed t-test of ``a`` against ``b``, as
    ``psa-esp report`` computes it: ``(t, df, p)``; NaN for all three where
    either sample has fewer than 2 values."""

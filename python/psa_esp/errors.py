"""The exceptions psa_esp raises, each with the crate's message.

Every one is a :class:`PsaEspError`; those about a value you passed are
also :class:`ValueError` (and catching ``ValueError`` catches them too).
Wrong array types raise :class:`TypeError`, wrong shapes and non-finite
weights :class:`ValueError`, as NumPy would.
"""


class PsaEspError(Exception):
    """Base of every psa_esp error."""


class ConfigError(PsaEspError, ValueError):
    """A configuration that cannot be read: an unknown setting, an
    out-of-range value (named as in a TOML file, with its range), a TOML
    file that cannot be read or parsed, an unknown preset or backend."""


class SettingsError(ConfigError):
    """A search setting (ESP's or the hill-climber's) or a stop condition
    out of its range."""


class NetworkFileError(PsaEspError, ValueError):
    """A network file that cannot be read or written; names the file."""


class SimulationError(PsaEspError, RuntimeError):
    """The simulator failed on a network (a physics error)."""


class RunError(PsaEspError, RuntimeError):
    """Base of the errors of a run driven by ask and tell (the crate's
    ``RunError``). A tell that raises leaves the run as it was."""


class EvaluationError(RunError):
    """The evaluation of the asked networks failed."""


class NanFitnessError(RunError, ValueError):
    """A told fitness is NaN."""


class InfiniteFitnessError(RunError, ValueError):
    """A told fitness is infinite: fitness must be finite."""


class FitnessCountError(RunError, ValueError):
    """Told another number of fitnesses than networks asked."""


class ForeignTicketError(RunError):
    """The ticket belongs to another run (or to this run before it was
    saved and restored)."""


class TicketToldError(RunError):
    """The ask of this ticket was told already: ask again, then tell."""


class EndedError(RunError):
    """The run has ended: it asks for no more networks."""


class NotEndedError(RunError):
    """The run's result was asked for before it ended."""


class RestoreError(RunError):
    """A saved run that cannot be restored."""


class NonFiniteWeightError(RunError):
    """The search's weights overflowed (its mutation settings let them)."""


__all__ = [
    "PsaEspError",
    "ConfigError",
    "SettingsError",
    "NetworkFileError",
    "SimulationError",
    "RunError",
    "EvaluationError",
    "NanFitnessError",
    "InfiniteFitnessError",
    "FitnessCountError",
    "ForeignTicketError",
    "TicketToldError",
    "EndedError",
    "NotEndedError",
    "RestoreError",
    "NonFiniteWeightError",
]

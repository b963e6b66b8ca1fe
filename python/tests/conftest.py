"""Shared fixtures: the psa-esp command line to compare with, and
networks that score (an evolved champion per task)."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import psa_esp

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    """Runs the psa-esp binary (PSA_ESP_CLI, else target/release/psa-esp)
    and returns its standard output; a test needing it is skipped where
    it is not built, unless PSA_ESP_REQUIRE_CLI is set (CI sets it)."""
    path = Path(os.environ.get("PSA_ESP_CLI", REPO / "target" / "release" / "psa-esp"))
    if not path.exists():
        if os.environ.get("PSA_ESP_REQUIRE_CLI"):
            pytest.fail(f"the psa-esp binary {path} is not built (cargo build --release)")
        pytest.skip(f"the psa-esp binary {path} is not built (cargo build --release)")

    def run(*args):
        done = subprocess.run([str(path), *map(str, args)], capture_output=True, text=True, check=False)
        assert done.returncode == 0, f"psa-esp {' '.join(map(str, args))}: {done.stderr}"
        return done.stdout

    run.json = lambda *args: json.loads(run(*args, "--json"))
    return run


@pytest.fixture(scope="session")
def champions():
    """A short ESP run's champion per task (weights (hidden, 11)), which
    scores well above zero, unlike random networks."""
    found = {}
    for task in psa_esp.TASKS:
        result = psa_esp.evolve(task, seed=11, generations=25)
        assert result["champion"]["fitness"] > 0
        found[task] = result["champion"]["weights"]
    return found


def random_networks(count, hidden=5, seed=0, scale=3.0):
    """`count` random networks (count, hidden, 11), weights uniform in (-scale, scale)."""
    rng = np.random.default_rng(seed)
    return rng.uniform(-scale, scale, size=(count, hidden, psa_esp.GENES_PER_NEURON))

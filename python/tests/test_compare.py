"""The CMA-ES comparison's records: each run's file names its build,
model and versions, and the report refuses runs of another model."""

from __future__ import annotations

import importlib.util
import json
import os

import numpy as np
import pytest

import psa_esp

from conftest import REPO


@pytest.fixture(scope="module")
def compare():
    spec = importlib.util.spec_from_file_location("compare_cmaes", REPO / "python" / "examples" / "compare_cmaes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def row(compare, algorithm, seed, **changes):
    record = {
        "algorithm": algorithm,
        "task": 1,
        "seed": seed,
        "fitness": 10.0 + seed,
        "score": 5.0 + seed,
        "evaluations": 100,
        "hidden": 5,
        "seconds": 1.0,
        "curve_step": compare.CURVE_STEP,
        "curve": [1.0],
        "weights": np.zeros((5, 11)).tolist(),
        **compare.provenance(),
    }
    record.update(changes)
    return record


def test_runs_record_their_build_model_and_versions(compare):
    made = compare.provenance()
    assert made["build"] == psa_esp.build
    assert made["model"] == psa_esp.resolve_config()
    assert made["versions"]["numpy"] == np.__version__
    assert "cma" in made["versions"]
    # CMA-ES's bits depend on NumPy's BLAS, its threads and the processor.
    assert made["blas"]["name"] == np.show_config(mode="dicts")["Build Dependencies"]["blas"]["name"]
    assert made["blas"]["threads"]["OPENBLAS_NUM_THREADS"] == os.environ.get("OPENBLAS_NUM_THREADS")
    assert made["cpu"]["cores"] == os.cpu_count() and made["cpu"]["model"]


def test_the_report_refuses_runs_of_another_model(compare, tmp_path):
    for seed in (1, 2):
        for algorithm in ("esp", "cma-es"):
            (tmp_path / f"{algorithm}-task1-seed{seed}.json").write_text(json.dumps(row(compare, algorithm, seed)))
    compare.report(tmp_path)
    table = (tmp_path / "table.md").read_text()
    assert psa_esp.build in table
    stale = row(compare, "esp", 3, model=psa_esp.resolve_config().replace("500", "600", 1))
    (tmp_path / "esp-task1-seed3.json").write_text(json.dumps(stale))
    with pytest.raises(SystemExit, match="another model"):
        compare.report(tmp_path)
    old = row(compare, "esp", 3)
    del old["model"]
    (tmp_path / "esp-task1-seed3.json").write_text(json.dumps(old))
    with pytest.raises(SystemExit, match="esp-task1-seed3.json"):
        compare.report(tmp_path)

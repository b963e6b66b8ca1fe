"""How fast psa_esp.evaluate is beside the command line's batched
evaluation, on the same host, in one run.

    python benchmarks/evaluate.py [--networks 4096] [--rounds 7] [--threads N] [--cli target/release/psa-esp]

The reference is the crate's own batched evaluation, timed without Python
(`esp_neuroevolution::evaluate_all` over psa-sim's evaluator on the
fastest path: what `psa-esp bench` times for its rows of evaluations per
second); the two are timed in alternation, round by round, on the same
networks, so that a shared host's noise hits them alike, and the ratio of
their medians is printed. With --cli, `psa-esp bench --networks N` runs
once as well and its native batched rows are printed beside.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import time

import numpy as np

import psa_esp
from psa_esp._native import reference_evaluations_per_second


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--networks", type=int, default=4096)
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--threads", type=int, default=None, help="threads (default: one per core)")
    parser.add_argument("--task", type=int, default=1)
    parser.add_argument("--cli", default=None, help="the psa-esp binary, to run its bench once as well")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    weights = rng.uniform(-6.0, 6.0, size=(args.networks, 5, psa_esp.GENES_PER_NEURON))
    psa_esp.evaluate(weights[:64], args.task, threads=args.threads)
    python_rates, reference_rates = [], []
    for _ in range(args.rounds):
        start = time.perf_counter()
        psa_esp.evaluate(weights, args.task, threads=args.threads)
        python_rates.append(args.networks / (time.perf_counter() - start))
        reference_rates += reference_evaluations_per_second(weights, args.task, rounds=1, threads=args.threads)
    python, reference = statistics.median(python_rates), statistics.median(reference_rates)
    summary = {
        "networks": args.networks,
        "rounds": args.rounds,
        "threads": args.threads,
        "task": args.task,
        "evaluate_per_second": python,
        "reference_per_second": reference,
        "ratio": python / reference,
        "build": psa_esp.build,
    }
    if args.cli:
        bench = json.loads(
            subprocess.run(
                [args.cli, "bench", "--networks", str(args.networks), "--rounds", "1", "--steps", "500",
                 "--generations", "2", "--json"],
                capture_output=True, text=True, check=True,
            ).stdout
        )
        summary["cli_bench_rows"] = [
            row for row in bench.get("psa_evaluation", []) if row["path"]["backend"] == "native" and row["path"]["simd"] and not row["path"]["input_noise"]
        ]
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(
            f"{args.networks} networks, task {args.task}, threads {args.threads or 'one per core'}, "
            f"median of {args.rounds} rounds:\n"
            f"  psa_esp.evaluate     {python:10.0f} evaluations/s\n"
            f"  crate, no Python     {reference:10.0f} evaluations/s\n"
            f"  ratio                {python / reference:10.3f}"
        )
        for row in summary.get("cli_bench_rows", []):
            print(f"  psa-esp bench, {row['path']['simd']}: {row}")


if __name__ == "__main__":
    main()

"""CMA-ES (pycma) against ESP and the hill-climber on the PSA's tasks 1-3,
each with the paper's evaluation budget (400 networks x 2000 generations =
800,000 network evaluations), 10 seeds each.

    python examples/compare_cmaes.py --out examples/results          # the runs (resumable)
    python examples/compare_cmaes.py --out examples/results --report # table and figure

Runs go seed by seed (every task and algorithm of a seed before the
next seed), each writing its own JSON file into --out as it finishes; running the
same command again skips the runs already there, so a killed comparison
loses no finished run. ESP and the hill-climber are psa-esp's presets
`baseline` and `hill-climb` (`psa_esp.evolve`: what `psa-esp evolve
--backend native` runs); CMA-ES searches the weights of a network of 5
hidden neurons (55 weights, the hill-climber's size) on the very fitness
they maximise (`psa_esp.evaluate`, the incremental fitness in % of the
maximum), 400 networks a generation, restarted with a new seed whenever it
stops before the budget is spent.

Reported per run: the champion's evolution fitness (what the search
maximised) and its score on Sit's original fitness, flown once from the
standard start (the paper's Table 1, as the replication's report
measures it). Each run's file records what made it: the package's build,
the model's settings (the baseline configuration, resolved) and the
versions of pycma and NumPy; `--report` refuses files of another model
(made by a build whose defaults differ: run them again).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import time
from pathlib import Path

# pycma's eigendecompositions of a 55 x 55 matrix run four times faster on
# one BLAS thread than on OpenBLAS's default of one per core (0.06 against
# 0.24 s a generation on the 2-core development host), and the evaluation
# threads then keep the cores. Set before NumPy loads OpenBLAS.
for _blas in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_blas, "1")

import numpy as np  # noqa: E402

import psa_esp  # noqa: E402

BUDGET = 400 * 2000
POPULATION = 400
HIDDEN = 5
ALGORITHMS = ("esp", "hill-climb", "cma-es")
TASKS = (1, 2, 3)
SCORING = {"problem": {"fitness": {"kind": "original"}}}
#: The champion's fitness after every CURVE_STEP evaluations, for the figure.
CURVE_STEP = 8000


def model():
    """The model's settings the runs are made on: the baseline
    configuration on the package's default backend, as TOML."""
    return psa_esp.resolve_config(preset="baseline")


def cpu():
    """The processor: `lscpu`'s model name and CPU family (from
    /proc/cpuinfo), or what `platform` knows elsewhere."""
    fields = {}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            fields.setdefault(key.strip(), value.strip())
    except OSError:
        pass
    name = fields.get("model name") or platform.processor() or platform.machine()
    return {"model": name, "family": fields.get("cpu family"), "cores": os.cpu_count()}


def blas():
    """NumPy's BLAS (CMA-ES's linear algebra, which decides its bits) and
    the threads it was allowed."""
    try:
        info = np.show_config(mode="dicts")["Build Dependencies"]["blas"]
    except (KeyError, TypeError):
        info = {}
    return {
        "name": info.get("name"),
        "version": info.get("version"),
        "configuration": info.get("openblas configuration"),
        "threads": {var: os.environ.get(var) for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")},
    }


def provenance():
    """What made a run: the build, the model's settings, the versions of
    the package, pycma and NumPy, NumPy's BLAS and its threads, and the
    processor (CMA-ES's results depend on the last two)."""
    try:
        import cma

        cma_version = cma.__version__
    except ImportError:
        cma_version = None
    return {
        "build": psa_esp.build,
        "model": model(),
        "versions": {"psa_esp": psa_esp.__version__, "cma": cma_version, "numpy": np.__version__},
        "blas": blas(),
        "cpu": cpu(),
    }


def curve_from_records(records):
    """The champion's fitness at every CURVE_STEP evaluations."""
    points, k = [], 0
    for mark in range(CURVE_STEP, BUDGET + 1, CURVE_STEP):
        while k + 1 < len(records) and records[k + 1]["evaluations"] <= mark:
            k += 1
        points.append(records[k]["champion"] if records[k]["evaluations"] <= mark else 0.0)
    return points


def run_search(algorithm, task, seed, threads):
    """One run: its champion's weights, fitness, evaluations and curve."""
    if algorithm in ("esp", "hill-climb"):
        preset = "baseline" if algorithm == "esp" else "hill-climb"
        result = psa_esp.evolve(task, preset, seed=seed, threads=threads)
        records = result["records"]
        return result["champion"], records[-1]["evaluations"], curve_from_records(records)
    import cma
    import cma.evolution_strategy

    # pycma keeps every sent solution in a dictionary for its bounds and
    # transformations, neither of which is used here; with 400 solutions a
    # generation the dictionary was most of its time.
    cma.evolution_strategy.archive_sent_solutions = False

    rng = np.random.default_rng(seed)
    genes = HIDDEN * psa_esp.GENES_PER_NEURON
    best = {"fitness": -math.inf, "weights": None}
    evaluations, restart, history = 0, 0, []
    while evaluations < BUDGET:
        options = {
            "popsize": POPULATION,
            "seed": seed * 1000 + restart + 1,
            "maxfevals": BUDGET - evaluations,
            "verbose": -9,
        }
        es = cma.CMAEvolutionStrategy(rng.uniform(-1.0, 1.0, genes), 3.0, options)
        while not es.stop() and evaluations < BUDGET:
            candidates = np.asarray(es.ask())
            fitness = psa_esp.evaluate(candidates.reshape(-1, HIDDEN, psa_esp.GENES_PER_NEURON), task, threads=threads)
            es.tell(candidates, (-fitness).tolist())
            evaluations += len(candidates)
            j = int(np.argmax(fitness))
            if fitness[j] > best["fitness"]:
                best = {"fitness": float(fitness[j]), "weights": candidates[j].reshape(HIDDEN, -1)}
            history.append({"evaluations": evaluations, "champion": best["fitness"]})
        restart += 1
    return best, evaluations, curve_from_records(history)


def run_all(out: Path, seeds: int, threads: int | None):
    out.mkdir(parents=True, exist_ok=True)
    for seed in range(1, seeds + 1):
        for task in TASKS:
            for algorithm in ALGORITHMS:
                path = out / f"{algorithm}-task{task}-seed{seed}.json"
                if path.exists():
                    continue
                start = time.perf_counter()
                champion, evaluations, curve = run_search(algorithm, task, seed, threads)
                weights = np.asarray(champion["weights"], dtype=np.float64)
                score = float(psa_esp.evaluate(weights[None], task, SCORING)[0])
                row = {
                    "algorithm": algorithm,
                    "task": task,
                    "seed": seed,
                    "fitness": champion["fitness"],
                    "score": score,
                    "evaluations": evaluations,
                    "hidden": int(weights.shape[0]),
                    "seconds": time.perf_counter() - start,
                    "curve_step": CURVE_STEP,
                    "curve": curve,
                    "weights": weights.tolist(),
                    **provenance(),
                }
                tmp = path.with_suffix(".tmp")
                tmp.write_text(json.dumps(row))
                tmp.replace(path)
                print(
                    f"{algorithm:10} task {task} seed {seed:2}: fitness {row['fitness']:6.2f} "
                    f"score {score:6.2f} ({evaluations} evaluations, {row['seconds']:.0f} s)",
                    flush=True,
                )


def load_rows(out: Path):
    """The runs in `out`, all of today's model; exits naming the files of
    another (or no recorded) model."""
    paths = sorted(out.glob("*-task*-seed*.json"))
    rows = [json.loads(p.read_text()) for p in paths]
    today = model()
    stale = [p.name for p, r in zip(paths, rows) if r.get("model") != today]
    if stale:
        raise SystemExit(
            f"{len(stale)} of {len(rows)} runs in {out} were made on another model than this build's "
            f"({psa_esp.build}), or record none: {', '.join(stale[:5])}{' ...' if len(stale) > 5 else ''}. "
            "Run them again (move them away first)."
        )
    return rows


def report(out: Path):
    rows = load_rows(out)
    lines = [
        "| task | algorithm | runs | fitness (mean ± se) | score (mean ± se) | t vs ESP, score (df, p) | hidden | s/run |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]

    def se(x):
        return x.std(ddof=1) / math.sqrt(len(x)) if len(x) > 1 else float("nan")

    for task in (*TASKS, "all"):
        on_task = [r for r in rows if task == "all" or r["task"] == task]
        esp = [r["score"] for r in on_task if r["algorithm"] == "esp"]
        for algorithm in ALGORITHMS:
            runs = [r for r in on_task if r["algorithm"] == algorithm]
            if not runs:
                continue
            fitness = np.array([r["fitness"] for r in runs])
            score = np.array([r["score"] for r in runs])
            t = ""
            if algorithm != "esp":
                # The report's own Welch test (psa-esp report's tables).
                tt, df, p = psa_esp.welch(score.tolist(), esp)
                t = f"{tt:+.2f} ({df:.0f}, {p:.2g})"
            lines.append(
                f"| {task} | {algorithm} | {len(runs)} | {fitness.mean():.2f} ± {se(fitness):.2f} "
                f"| {score.mean():.2f} ± {se(score):.2f} | {t} | {np.mean([r['hidden'] for r in runs]):.1f} "
                f"| {np.mean([r['seconds'] for r in runs]):.0f} |"
            )
    builds = sorted({r["build"] for r in rows})
    versions = sorted({f"pycma {r['versions']['cma']}, NumPy {r['versions']['numpy']}" for r in rows})
    # Files of earlier builds record no BLAS or processor.
    hosts = sorted(
        {
            f"{r['blas']['name']} {r['blas']['version']} on {r['cpu']['model']} (family {r['cpu']['family']})"
            if "blas" in r
            else "BLAS and processor not recorded"
            for r in rows
        }
    )
    lines.append("")
    lines.append(f"Made on psa-esp {', '.join(builds)} ({'; '.join(versions)}), the model of `psa_esp.resolve_config()`.")
    lines.append(f"CMA-ES's bits depend on the BLAS and the processor: {'; '.join(hosts)}.")
    table = "\n".join(lines)
    (out / "table.md").write_text(table + "\n")
    print(table)
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no figure (pip install matplotlib)")
        return
    fig, axes = plt.subplots(1, len(TASKS), figsize=(13, 3.8), sharey=False)
    colours = {"esp": "tab:blue", "hill-climb": "tab:orange", "cma-es": "tab:green"}
    for ax, task in zip(axes, TASKS):
        for algorithm in ALGORITHMS:
            runs = [r for r in rows if r["task"] == task and r["algorithm"] == algorithm]
            if not runs:
                continue
            curves = np.array([r["curve"] for r in runs])
            x = np.arange(1, curves.shape[1] + 1) * runs[0]["curve_step"]
            mean = curves.mean(axis=0)
            ax.plot(x, mean, color=colours[algorithm], label=f"{algorithm} ({len(runs)} runs)")
            lo, hi = curves.min(axis=0), curves.max(axis=0)
            ax.fill_between(x, lo, hi, color=colours[algorithm], alpha=0.15)
        ax.set_title(f"task {task}")
        ax.set_xlabel("network evaluations")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("champion's fitness (% of maximum)")
    axes[0].legend(loc="lower right", fontsize=8)
    fig.suptitle("Champion's evolution fitness by evaluations: mean over seeds, band min-max")
    fig.tight_layout()
    fig.savefig(out / "cmaes-esp-hill-climb.png", dpi=110)
    print(f"wrote {out / 'cmaes-esp-hill-climb.png'} and {out / 'table.md'}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("examples/results"))
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--threads", type=int, default=None, help="evaluation threads (default: one per core)")
    parser.add_argument("--report", action="store_true", help="only write the table and the figure")
    args = parser.parse_args()
    if not args.report:
        run_all(args.out, args.seeds, args.threads)
    report(args.out)


if __name__ == "__main__":
    main()

"""ESP and the hill-climber from Python: the command line's runs bit for
bit, ask/tell misuse raising the crate's errors, save and resume, the
progress callback, a fitness function of the user's, champion files."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import psa_esp


def records_of(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def as_csv_row(record):
    """A record as records.csv writes it (Rust's shortest float text)."""
    text = {True: "true", False: "false", None: ""}

    def cell(value):
        if isinstance(value, bool) or value is None:
            return text[value]
        if isinstance(value, float):
            return repr(value).removesuffix(".0") if value.is_integer() else repr(value)
        return str(value)

    return {k: cell(v) for k, v in record.items()}


@pytest.mark.parametrize(("preset", "task", "generations"), [("baseline", 1, 60), ("hill-climb", 3, 40)])
def test_evolve_makes_the_run_psa_esp_evolve_makes(cli, tmp_path, preset, task, generations):
    mine, theirs = tmp_path / "python", tmp_path / "cli"
    result = psa_esp.evolve(task, preset, seed=4, generations=generations, out=mine)
    cli("evolve", "--task", task, "--preset", preset, "--seed", 4, "--generations", generations,
        "--backend", "native", "--out", theirs)
    assert (mine / "records.csv").read_text() == (theirs / "records.csv").read_text()
    assert (mine / "config.toml").read_text() == (theirs / "config.toml").read_text()
    cli_champion = json.loads((theirs / "champion.json").read_text())
    py_champion = json.loads((mine / "champion.json").read_text())
    assert py_champion["neurons"] == cli_champion["neurons"]
    assert py_champion["problem"] == cli_champion["problem"]
    assert py_champion["provenance"]["fitness_percent"] == cli_champion["provenance"]["fitness_percent"]
    assert [as_csv_row(r) for r in result["records"]] == records_of(theirs / "records.csv")
    loaded = psa_esp.load_network(theirs / "champion.json")
    assert np.array_equal(loaded.weights, result["champion"]["weights"])


def test_ask_tell_with_evaluate_psa_is_run_psa(tmp_path):
    run = psa_esp.Run(seed=8, generations=30)
    purposes = set()
    while (asked := run.ask()) is not None:
        purposes.add(asked.purpose)
        assert asked.weights.shape[0] == len(asked) and asked.weights.shape[2] == 11
        run.tell(asked.ticket, run.evaluate_psa(asked, 2))
    native = psa_esp.Run(seed=8, generations=30).run_psa(2)
    assert run.result()["records"] == native["records"]
    assert run.ending == "completed"
    assert "generation" in purposes


def test_asked_weights_evaluate_as_the_crate_evaluates_them():
    # With a deterministic problem, any evaluator of the asked weights as
    # they are (lesioned neurons as zeros) scores what the crate does.
    run = psa_esp.Run(seed=2, generations=200, config={"esp": {"stagnation": 3, "bursts_before_lesion": 1}})
    lesion_tests = 0
    while (asked := run.ask()) is not None:
        fitness = run.evaluate_psa(asked, 1)
        if asked.purpose == "lesion_test":
            lesion_tests += 1
            assert asked.lesioned.any()
            assert np.array_equal(psa_esp.evaluate(asked.weights, 1), fitness)
        run.tell(asked.ticket, fitness)
        if lesion_tests >= 2:
            break
    assert lesion_tests >= 2


def small_run(**kwargs):
    return psa_esp.Run(seed=3, generations=6, config={"esp": {"subpop_size": 10, "trials_per_neuron": 2}}, **kwargs)


def test_ask_tell_misuse_raises_the_crates_errors_and_changes_nothing():
    run, other = small_run(), small_run()
    asked = run.ask()
    fitness = run.evaluate_psa(asked, 1)
    with pytest.raises(psa_esp.ForeignTicketError, match="another run"):
        run.tell(other.ask().ticket, fitness)
    with pytest.raises(psa_esp.FitnessCountError, match=f"told {len(asked) - 1} fitnesses for the {len(asked)}"):
        run.tell(asked.ticket, fitness[:-1])
    bad = fitness.copy()
    bad[3] = np.nan
    with pytest.raises(psa_esp.NanFitnessError, match="network 3"):
        run.tell(asked.ticket, bad)
    bad[3] = -np.inf
    with pytest.raises(psa_esp.InfiniteFitnessError, match="network 3"):
        run.tell(asked.ticket, bad)
    with pytest.raises(TypeError, match="dtype int64"):
        run.tell(asked.ticket, fitness.astype(np.int64))
    with pytest.raises(ValueError, match="one dimension"):
        run.tell(asked.ticket, fitness[:, None])
    with pytest.raises(TypeError, match="Ticket"):
        run.tell("ticket", fitness)
    with pytest.raises(psa_esp.NotEndedError):
        run.result()
    run.tell(asked.ticket, fitness)
    with pytest.raises(psa_esp.TicketToldError, match="told already"):
        run.tell(asked.ticket, fitness)
    last = asked
    while (asked := run.ask()) is not None:
        run.tell(asked.ticket, run.evaluate_psa(asked, 1))
        last = asked
    with pytest.raises(psa_esp.EndedError):
        run.tell(last.ticket, run.evaluate_psa(last, 1))
    assert run.ask() is None
    assert run.result()["records"] == small_run().run_psa(1)["records"], "the errors changed nothing"
    assert issubclass(psa_esp.ForeignTicketError, psa_esp.RunError)


def test_bad_run_settings_raise_clear_exceptions():
    with pytest.raises(psa_esp.ConfigError, match="subpop_size"):
        psa_esp.Run(config={"esp": {"subpop_size": 1}})
    with pytest.raises(psa_esp.SettingsError, match="goal"):
        psa_esp.Run(goal=float("nan"))
    with pytest.raises(ValueError, match="algorithm"):
        psa_esp.Run("cma")
    with pytest.raises(psa_esp.ConfigError, match="generations"):
        psa_esp.Run(generations=0)


@pytest.mark.parametrize("algorithm", ["esp", "hill_climb"])
def test_a_run_saved_anywhere_and_resumed_ends_bit_for_bit_as_one_never_stopped(algorithm):
    config = {"esp": {"subpop_size": 10, "trials_per_neuron": 2, "stagnation": 3, "bursts_before_lesion": 1},
              "hill_climb": {"candidates": 20}}

    def fresh():
        return psa_esp.Run(algorithm, seed=5, generations=40, config=config)

    whole = fresh()
    whole_result = whole.run_psa(3)
    for stop_after in [0, 1, 7, 23]:
        run = fresh()
        for _ in range(stop_after):
            asked = run.ask()
            run.tell(asked.ticket, run.evaluate_psa(asked, 3))
        pending = run.ask()
        saved = run.to_json()
        restored = psa_esp.Run.from_json(saved)
        assert restored.to_json() == saved
        again = restored.ask()
        assert np.array_equal(again.weights, pending.weights)
        with pytest.raises(psa_esp.ForeignTicketError):
            restored.tell(pending.ticket, run.evaluate_psa(pending, 3))
        result = restored.run_psa(3)
        assert result["records"] == whole_result["records"]
        assert np.array_equal(result["champion"]["weights"], whole_result["champion"]["weights"])
        assert result["champion"]["fitness"] == whole_result["champion"]["fitness"]
    assert whole.to_json() == restored.to_json()


def test_a_damaged_save_raises_restore_error():
    saved = json.loads(small_run().to_json())
    with pytest.raises(psa_esp.RestoreError):
        psa_esp.Run.from_json("{}")
    with pytest.raises(psa_esp.RestoreError):
        psa_esp.Run.from_json("not json")
    saved["seed"] = "99"
    with pytest.raises(psa_esp.RestoreError, match="seed"):
        psa_esp.Run.from_json(json.dumps(saved))


def test_the_progress_callback_sees_every_generation_and_can_stop_the_run():
    seen = []
    result = small_run().run_psa(1, lambda record: seen.append(record))
    assert [r["generation"] for r in seen] == list(range(1, 7))
    assert seen == result["records"]
    stopped = small_run().run_psa(1, lambda record: record["generation"] == 3)
    assert stopped["ending"] == "stopped" and len(stopped["records"]) == 3
    assert stopped["records"] == result["records"][:3]
    with pytest.raises(ZeroDivisionError):
        small_run().run_psa(1, lambda record: 1 / 0)


def logistic(x):
    return 1.0 / (1.0 + np.exp(-x))


def follow_the_input(weights):
    """Fitness of 2-H-1 networks (input x, bias) at making the output follow x."""
    xs = np.linspace(0.0, 1.0, 5)
    inputs = np.stack([xs, np.ones_like(xs)], axis=1)
    hidden = logistic(np.einsum("nhi,ci->nch", weights[:, :, :2], inputs))
    outputs = logistic(np.einsum("nch,nh->nc", hidden, weights[:, :, 2]))
    return -((outputs - xs) ** 2).sum(axis=1)


def test_a_fitness_function_of_ones_own_works_as_well():
    def make():
        return psa_esp.Run(seed=7, inputs=2, outputs=1, generations=40,
                           config={"esp": {"subpop_size": 20, "initial_hidden": 2}})

    records = []
    result = make().optimize(follow_the_input, records.append)
    assert result["champion"]["fitness"] > -0.05
    assert result["champion"]["weights"].shape[1] == 3
    assert len(records) == 40
    run = make()
    while (asked := run.ask()) is not None:
        run.tell(asked.ticket, follow_the_input(asked.weights).tolist())
    assert run.result()["records"] == result["records"]
    with pytest.raises(psa_esp.FitnessCountError):
        make().optimize(lambda weights: np.zeros(3))


def test_a_champion_replayed_from_python_scores_what_psa_esp_replay_prints(cli, tmp_path):
    run = psa_esp.Run(seed=6, generations=30)
    result = run.run_psa(1)
    path = tmp_path / "champion.json"
    run.save_champion(path, 1)
    printed = cli.json("replay", path, "--backend", "native", "--out", tmp_path / "replay")
    assert printed["fitness_percent_mean"] == result["champion"]["fitness"]
    assert psa_esp.replay(path, backend="native")["fitness_percent_mean"] == result["champion"]["fitness"]
    assert cli.json("replay", path, "--out", tmp_path / "r2")["fitness_percent_mean"] == psa_esp.replay(path)[
        "fitness_percent_mean"
    ]
    network = psa_esp.load_network(path)
    assert network.task == 1 and network.provenance["seed"] == "6"
    assert np.array_equal(network.weights, result["champion"]["weights"])


def test_network_files_round_trip_and_bad_files_raise(tmp_path):
    weights = np.random.default_rng(1).normal(size=(4, 11))
    network = psa_esp.Network(weights, 2, provenance={"note": "hand-made"})
    path = tmp_path / "net.json"
    network.save(path)
    loaded = psa_esp.load_network(path)
    assert np.array_equal(loaded.weights, weights)
    assert loaded.provenance["note"] == "hand-made" and loaded.task == 2
    assert loaded.problem["backend"] == "native"
    (tmp_path / "bad.json").write_text('{"format": "something else"}')
    with pytest.raises(psa_esp.NetworkFileError, match="bad.json"):
        psa_esp.load_network(tmp_path / "bad.json")
    with pytest.raises(psa_esp.NetworkFileError, match="missing.json"):
        psa_esp.load_network(tmp_path / "missing.json")
    with pytest.raises(ValueError, match="not finite"):
        psa_esp.Network(np.full((2, 11), np.nan))
    with pytest.raises(ValueError, match="random_init"):
        psa_esp.replay(path, random_init=True)


def test_result_during_the_run_is_the_best_so_far():
    run = psa_esp.Run(seed=5, generations=4)
    with pytest.raises(psa_esp.NotEndedError):
        run.result()
    best = -np.inf
    for _ in range(2):
        asked = run.ask()
        fitness = run.evaluate_psa(asked, 1)
        run.tell(asked.ticket, fitness)
        best = max(best, float(fitness.max()))
    result = run.result()
    assert result["ending"] is None
    assert result["champion"]["fitness"] == best
    assert len(result["records"]) == len(run.records)
    weights = result["champion"]["weights"]
    assert psa_esp.evaluate(weights[None], 1, seed=run.seed, trials=None).shape == (1,)
    final = run.run_psa(1)
    assert final["champion"]["fitness"] >= best
    assert run.result()["ending"] == final["ending"] == "completed"
    assert run.result()["champion"]["fitness"] == final["champion"]["fitness"]


def test_a_network_activates_a_batch_as_it_activates_each_observation():
    network = psa_esp.Network(np.random.default_rng(3).normal(size=(5, 11)), 1)
    observations = np.random.default_rng(4).normal(size=(9, psa_esp.INPUTS))
    batch = network.activate(observations)
    assert batch.shape == (9, psa_esp.OUTPUTS)
    for observation, outputs in zip(observations, batch):
        assert np.array_equal(network.activate(observation), outputs)
        assert np.array_equal(network.activate(observation.tolist()), outputs)
    assert network.activate(observations[:0]).shape == (0, psa_esp.OUTPUTS)
    with pytest.raises(ValueError, match=r"shape \(N, 7\), got shape \[9, 6\]"):
        network.activate(observations[:, :6])
    with pytest.raises(TypeError, match="got str"):
        network.activate("seven")


def test_environments_and_trials_say_what_they_are():
    from psa_esp.env import PsaEnv

    env = PsaEnv(2, preset="max-credit")
    assert repr(env) == "PsaEnv(task=2, preset='max-credit'; Trial(task=2, backend='native', not started))"
    env.reset(seed=1)
    env.step(np.zeros(4))
    assert repr(env._trial) == "Trial(task=2, backend='native', step 1 of 500, fitness 0.0 %)"

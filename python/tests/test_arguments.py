"""Types and arguments as NumPy users expect them: float32 arrays,
NumPy integers, negative counts, fresh seeds, both spellings of the
hill-climber, readable reprs."""

from __future__ import annotations

import re

import numpy as np
import pytest

import psa_esp

from conftest import random_networks


def test_float32_weights_and_fitness_are_converted_exactly():
    weights = random_networks(3).astype(np.float32)
    as32 = psa_esp.evaluate(weights, 1, trials=1)
    as64 = psa_esp.evaluate(weights.astype(np.float64), 1, trials=1)
    assert np.array_equal(as32, as64)
    run = psa_esp.Run(seed=2, generations=2)
    asked = run.ask()
    fitness = np.arange(len(asked), dtype=np.float32) / 7
    other = psa_esp.Run(seed=2, generations=2)
    other_asked = other.ask()
    run.tell(asked.ticket, fitness)
    other.tell(other_asked.ticket, fitness.astype(np.float64))
    assert run.to_json() == other.to_json()


def test_numpy_integers_are_integers_everywhere():
    weights = random_networks(2)
    plain = psa_esp.evaluate(weights, 1, seed=5, trials=2, threads=1)
    numpy = psa_esp.evaluate(weights, np.int64(1), seed=np.int64(5), trials=np.int32(2), threads=np.uint8(1))
    assert np.array_equal(plain, numpy)
    run = psa_esp.Run(seed=np.int64(3), generations=np.int64(2), inputs=np.int16(7), outputs=np.int16(4))
    assert run.seed == 3
    asked = run.ask()
    assert np.array_equal(run.evaluate_psa(asked, np.int64(1), threads=np.int64(1)), run.evaluate_psa(asked, 1))


@pytest.mark.parametrize("kwargs", [{"trials": -1}, {"threads": -1}, {"seed": -1}])
def test_negative_counts_raise_value_error(kwargs):
    with pytest.raises(ValueError, match=next(iter(kwargs))):
        psa_esp.evaluate(random_networks(1), 1, **kwargs)


def test_negative_run_counts_raise_value_error():
    with pytest.raises(ValueError, match="generations"):
        psa_esp.Run(generations=-1)
    with pytest.raises(ValueError, match="seed"):
        psa_esp.Run(seed=-1)
    run = psa_esp.Run(generations=1)
    with pytest.raises(ValueError, match="threads"):
        run.evaluate_psa(run.ask(), 1, threads=-1)


def test_seed_none_draws_fresh_entropy_and_records_it():
    first, second = psa_esp.Run(seed=None), psa_esp.Run(seed=None)
    assert first.seed != second.seed
    again = psa_esp.Run(seed=first.seed)
    assert np.array_equal(first.ask().weights, again.ask().weights)
    result = psa_esp.evolve(1, seed=None, generations=1)
    assert isinstance(result["seed"], int)
    again = psa_esp.evolve(1, seed=result["seed"], generations=1)
    assert again["champion"]["fitness"] == result["champion"]["fitness"]
    assert np.array_equal(again["champion"]["weights"], result["champion"]["weights"])
    weights = random_networks(2)
    fitness, seed = psa_esp.evaluate(weights, 1, {"problem": {"noise": {"input_sd": 0.1}}}, seed=None, trials=1, return_seed=True)
    assert np.array_equal(fitness, psa_esp.evaluate(weights, 1, {"problem": {"noise": {"input_sd": 0.1}}}, seed=seed, trials=1))
    _, other = psa_esp.evaluate(weights, 1, seed=None, trials=1, return_seed=True)
    assert other != seed


def test_both_spellings_of_the_hill_climber_are_accepted_everywhere():
    for name in ["hill_climb", "hill-climb"]:
        assert psa_esp.Run(name).algorithm == "hill_climb"
        assert psa_esp.Run(preset=name).algorithm == "hill_climb"
        assert psa_esp.Run(config={"algorithm": name}).algorithm == "hill_climb"
    assert psa_esp.resolve_config(preset="hill_climb") == psa_esp.resolve_config(preset="hill-climb")


def test_reprs_are_readable():
    run = psa_esp.Run(seed=4, generations=1)
    asked = run.ask()
    assert repr(asked) == f"<psa_esp.Asked {len(asked)} networks for generation 1, seed 4>"
    assert "Some" not in repr(asked)
    assert repr(asked.ticket).startswith("<psa_esp.Ticket ")
    assert "{" not in repr(asked.ticket) and "Ticket {" not in repr(asked.ticket)
    climber = psa_esp.Run("hill_climb", generations=1)
    assert re.fullmatch(r"<psa_esp.Asked \d+ networks for generation 1, seed 1>", repr(climber.ask()))


def test_replay_and_trial_integers_raise_value_error_naming_the_argument(tmp_path):
    network = psa_esp.Network(random_networks(1)[0])
    for kwargs in [{"trials": -1}, {"seed": -1}, {"seed": 2**64}]:
        name = next(iter(kwargs))
        with pytest.raises(ValueError, match=name):
            psa_esp.replay(network, 1, backend="native", **kwargs)
    trial = psa_esp.Trial(1, backend="native")
    for seed in [-1, 2**64]:
        with pytest.raises(ValueError, match="seed"):
            trial.reset(seed)


def test_an_environment_reset_with_a_seed_out_of_range_raises_value_error():
    from psa_esp.env import PsaEnv

    with pytest.raises(ValueError, match="seed"):
        PsaEnv(1).reset(seed=2**64)


def test_a_bool_is_no_task():
    with pytest.raises(TypeError, match="task"):
        psa_esp.Trial(True)
    with pytest.raises(TypeError, match="task"):
        psa_esp.Network(random_networks(1)[0], True)
    run = psa_esp.Run(seed=1, generations=1, config={"esp": {"subpop_size": 10, "trials_per_neuron": 2}})
    run.run_psa(1)
    with pytest.raises(TypeError, match="task"):
        run.save_champion("unused.json", True)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [({"inputs": 0}, "inputs"), ({"outputs": 0}, "outputs"), ({"inputs": 10**9}, "inputs"), ({"max_evaluations": 0}, "max_evaluations")],
)
def test_run_sizes_out_of_range_raise_value_error(kwargs, name):
    with pytest.raises(ValueError, match=name):
        psa_esp.Run(**kwargs)


def test_the_benchmark_refuses_a_bool_as_its_task():
    with pytest.raises(TypeError, match="task"):
        psa_esp._native.reference_evaluations_per_second(random_networks(1), True, rounds=1)

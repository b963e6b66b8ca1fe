"""Batched evaluation: the same bits as the command line, determinism
by seed, and clear exceptions for bad input."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest
from conftest import random_networks

import psa_esp

NOISY = {"problem": {"noise": {"input_sd": 0.05, "output_sd": 0.02}}}


def population(champions, task, count=6):
    """The champion of `task` and mutants of it, which score all sorts (under
    input noise too: mutants closer to a task-3 champion all coast to the
    same score)."""
    rng = np.random.default_rng(task)
    base = champions[task]
    return np.stack([base] + [base + rng.normal(0, 2.0, base.shape) for _ in range(count - 1)])


@pytest.mark.parametrize("task", [1, 2, 3])
def test_evaluate_gives_what_replay_prints(cli, champions, tmp_path, task):
    networks = population(champions, task)
    random_init = task != 2
    got = psa_esp.evaluate(networks, task, NOISY, seed=7, trials=3)
    got_random = psa_esp.evaluate(
        networks, task, {"problem": {"random_init": random_init, **NOISY["problem"]}}, seed=9, trials=2
    )
    for j, weights in enumerate(networks):
        path = tmp_path / f"net{j}.json"
        psa_esp.Network(weights, task, NOISY).save(path)
        common = ["--backend", "native", "--input-noise", "0.05", "--output-noise", "0.02", "--out", tmp_path / "replay"]
        printed = cli.json("replay", path, "--trials", 3, "--seed", 7, *common)
        assert printed["fitness_percent_mean"] == got[j]
        extra = ["--random-init"] if random_init else []
        printed = cli.json("replay", path, "--trials", 2, "--seed", 9, *extra, *common)
        assert printed["fitness_percent_mean"] == got_random[j]
    assert len(set(got.tolist())) > 1, "the networks should score differently"


def test_evaluate_on_ode_gives_what_replay_on_ode_prints(cli, champions, tmp_path):
    networks = population(champions, 1, count=3)
    got = psa_esp.evaluate(networks, 1, backend="ode")
    assert np.array_equal(got, psa_esp.evaluate(networks, 1))
    for j, weights in enumerate(networks):
        path = tmp_path / f"net{j}.json"
        psa_esp.Network(weights, 1).save(path)
        assert cli.json("replay", path, "--out", tmp_path / "replay")["fitness_percent_mean"] == got[j]


def test_python_replay_prints_what_the_cli_prints(cli, champions, tmp_path):
    path = tmp_path / "champion.json"
    psa_esp.Network(champions[3], 3).save(path)
    args = dict(input_noise=0.05, trials=4, seed=3, random_init=True)
    mine = psa_esp.replay(path, **args)
    theirs = cli.json(
        "replay", path, "--input-noise", 0.05, "--trials", 4, "--seed", 3, "--random-init", "--out", tmp_path / "r"
    )
    for key in ["fitness_percent_mean", "fitness_percent_sd", "fitness_percent_per_trial", "task", "backend"]:
        assert mine[key] == theirs[key], key
    assert psa_esp.replay(psa_esp.load_network(path), **args) == mine


def test_a_seed_gives_the_same_bits_on_any_thread_count_path_and_layout(champions):
    networks = population(champions, 1, count=40)
    first = psa_esp.evaluate(networks, 1, NOISY, seed=5, trials=3)
    assert np.array_equal(first, psa_esp.evaluate(networks, 1, NOISY, seed=5, trials=3, threads=1))
    assert np.array_equal(first, psa_esp.evaluate(networks, 1, NOISY, seed=5, trials=3, eval_path="scalar"))
    flat = networks.reshape(len(networks), -1)
    assert np.array_equal(first, psa_esp.evaluate(flat, 1, NOISY, seed=5, trials=3))
    other = psa_esp.evaluate(networks, 1, NOISY, seed=6, trials=3)
    assert not np.array_equal(first, other), "another seed draws other noise"
    seeds = np.array([5, 6] * 20, dtype=np.uint64)
    mixed = psa_esp.evaluate(networks, 1, NOISY, seed=seeds, trials=3)
    assert np.array_equal(mixed[0::2], first[0::2]) and np.array_equal(mixed[1::2], other[1::2])


def test_a_lesioned_neuron_is_a_neuron_of_zero_weights(champions):
    networks = population(champions, 2, count=4)
    lesioned = np.zeros(networks.shape[:2], dtype=bool)
    lesioned[:, 1] = True
    zeroed = networks.copy()
    zeroed[:, 1, :] = 0.0
    assert np.array_equal(
        psa_esp.evaluate(networks, 2, lesioned=lesioned), psa_esp.evaluate(zeroed, 2)
    )


def test_a_config_file_is_a_dict(tmp_path, champions):
    path = tmp_path / "noisy.toml"
    path.write_text('[problem.noise]\ninput_sd = 0.05\noutput_sd = 0.02\n')
    networks = population(champions, 1)
    assert np.array_equal(
        psa_esp.evaluate(networks, 1, path, seed=2, trials=2), psa_esp.evaluate(networks, 1, NOISY, seed=2, trials=2)
    )
    assert 'input_sd = 0.05' in psa_esp.resolve_config(str(path))


def test_a_model_by_name_is_the_file_under_configs_and_an_unknown_one_is_refused():
    configs = pathlib.Path(__file__).resolve().parents[2] / "configs"
    named = psa_esp.resolve_config({"model": "positive-wrap"})
    assert named == psa_esp.resolve_config(str(configs / "positive-wrap.toml"))
    assert 'heading_wrap = "positive"' in named and named != psa_esp.resolve_config()
    with pytest.raises(ValueError, match="positive-wrap"):
        psa_esp.resolve_config({"model": "positive"})


def test_no_networks_is_no_fitness():
    assert psa_esp.evaluate(np.zeros((0, 5, 11)), 1).shape == (0,)


@pytest.mark.parametrize(
    ("weights", "error", "words"),
    [
        (random_networks(3).astype(np.int64), TypeError, "dtype int64"),
        ([["a"] * 55] * 3, TypeError, "got list"),
        ([np.zeros(55), np.zeros(44)], ValueError, "NumPy cannot read list"),
        (np.zeros((3, 5, 10)), ValueError, "10 genes per hidden neuron"),
        (np.zeros((3, 54)), ValueError, "not whole hidden neurons"),
        (np.zeros((2, 3, 5, 11)), ValueError, "4 dimensions"),
        (np.zeros(55), ValueError, "1 dimensions"),
        (np.zeros((3, 0, 11)), ValueError, "no hidden neuron"),
    ],
)
def test_bad_arrays_raise_clear_exceptions(weights, error, words):
    with pytest.raises(error, match=words):
        psa_esp.evaluate(weights, 1)


def test_a_nan_weight_names_its_network_and_neuron():
    weights = random_networks(4)
    weights[2, 3, 5] = np.nan
    with pytest.raises(ValueError, match="network 2: weight 5 of hidden neuron 3 is not finite"):
        psa_esp.evaluate(weights, 1)
    weights[2, 3, 5] = np.inf
    with pytest.raises(ValueError, match="not finite"):
        psa_esp.evaluate(weights, 1)


@pytest.mark.parametrize(
    ("kwargs", "error", "words"),
    [
        ({"config": {"problem": {"no_such_setting": 1}}}, psa_esp.ConfigError, "no_such_setting"),
        ({"config": {"problem": {"noise": {"input_sd": -1.0}}}}, psa_esp.ConfigError, "input_sd"),
        ({"config": {"problem": {"steps": "many"}}}, psa_esp.ConfigError, "steps"),
        ({"config": {"problem": {"steps": None}}}, psa_esp.ConfigError, "problem.steps"),
        ({"config": "/no/such/file.toml"}, psa_esp.ConfigError, "/no/such/file.toml"),
        ({"config": 5}, TypeError, "dict of settings or the path"),
        ({"trials": 0}, psa_esp.ConfigError, "trials"),
        ({"preset": "best"}, psa_esp.ConfigError, "unknown preset"),
        ({"backend": "bullet"}, psa_esp.ConfigError, "unknown backend"),
        ({"eval_path": "gpu"}, ValueError, "unknown evaluation path"),
        ({"seed": -1}, ValueError, "seed"),
        ({"seed": 2**64}, ValueError, "seed"),
        ({"seed": [1, 2]}, ValueError, "2 seeds for 3 networks"),
        ({"seed": 1.5}, TypeError, "seed must be an int"),
        ({"task": 4}, ValueError, "task must be 1, 2 or 3"),
        ({"threads": 5000}, ValueError, "threads"),
    ],
)
def test_bad_settings_raise_clear_exceptions(kwargs, error, words):
    kwargs = {"task": 1, **kwargs}
    with pytest.raises(error, match=words):
        psa_esp.evaluate(random_networks(3), **kwargs)


def test_a_config_error_is_a_value_error_and_a_package_error():
    with pytest.raises(ValueError) as caught:
        psa_esp.evaluate(random_networks(1), 1, {"esp": {"subpop_size": 0}})
    assert isinstance(caught.value, psa_esp.PsaEspError)
    assert "subpop_size" in str(caught.value)


def test_a_large_call_flown_in_pieces_gives_each_network_its_own_bits():
    # More networks than one piece between two signal checks (a thread's
    # 64 batches): the call's bits are each network's alone.
    networks = random_networks(1500, seed=4)
    whole = psa_esp.evaluate(networks, 1, NOISY, seed=np.arange(1500, dtype=np.uint64), threads=1)
    parts = [
        psa_esp.evaluate(networks[i : i + 100], 1, NOISY, seed=np.arange(i, i + 100, dtype=np.uint64), threads=1)
        for i in range(0, 1500, 100)
    ]
    assert np.array_equal(whole, np.concatenate(parts))


LONG_CALLS = {
    # Ten million trials on one thread: minutes of work.
    "evaluate": """
        networks = np.random.default_rng(0).uniform(-3, 3, (100_000, 5, psa_esp.GENES_PER_NEURON))
        started()
        psa_esp.evaluate(networks, 1, trials=100, threads=1)
        """,
    # One generation of 20,000 networks of 100 trials each on one thread.
    "Run.evaluate_psa": """
        run = psa_esp.Run(seed=1, config={"esp": {"subpop_size": 2000}, "problem": {"trials": 100}})
        asked = run.ask()
        started()
        run.evaluate_psa(asked, 1, threads=1)
        """,
}


@pytest.mark.parametrize("call", sorted(LONG_CALLS))
def test_ctrl_c_stops_a_long_evaluation_with_keyboard_interrupt(call):
    import signal
    import subprocess
    import sys
    import textwrap
    import time

    # Python's own handler, whatever the child inherits: a shell starts
    # background jobs with SIGINT ignored, and Python keeps that.
    script = "import signal\nsignal.signal(signal.SIGINT, signal.default_int_handler)\n"
    script += "import numpy as np, psa_esp\n"
    script += "def started():\n    print('started', flush=True)\n"
    script += "try:\n" + textwrap.indent(textwrap.dedent(LONG_CALLS[call]), "    ")
    script += "    print('finished')\nexcept KeyboardInterrupt:\n    print('interrupted')\n"
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "started"
    time.sleep(1)  # well inside the call, which runs for minutes
    child.send_signal(signal.SIGINT)
    try:
        out, err = child.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        child.kill()
        raise AssertionError(f"{call} did not stop on SIGINT") from None
    assert out.strip() == "interrupted", err


def test_a_sequence_of_equal_length_arrays_is_an_array():
    # pycma's ask() gives a list of flat arrays; other libraries' arrays
    # (here float32 rows) are read as NumPy reads them.
    networks = random_networks(5, seed=2)
    flat = networks.reshape(5, -1)
    expected = psa_esp.evaluate(networks, 2, seed=3)
    assert np.array_equal(psa_esp.evaluate(list(flat), 2, seed=3), expected)
    assert np.array_equal(psa_esp.evaluate(networks.tolist(), 2, seed=3), expected)
    rows32 = [row.astype(np.float32) for row in flat]
    assert np.array_equal(
        psa_esp.evaluate(rows32, 2, seed=3), psa_esp.evaluate(np.stack(rows32).astype(np.float64), 2, seed=3)
    )

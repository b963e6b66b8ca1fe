"""The installed package is portable: its extension finds libode inside
the wheel (python/build-wheel), not on the system, carries its own font,
and flies ODE as the command line does on the system's libode. CI
installs the portable wheel and sets PSA_ESP_REQUIRE_PORTABLE=1; an
editable or plain install (pip install ./python) links the system's
libode and uses the system's font."""

from __future__ import annotations

import csv
import os
import subprocess
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest

import psa_esp
import psa_esp._native

portable = pytest.mark.skipif(
    not os.environ.get("PSA_ESP_REQUIRE_PORTABLE"),
    reason="a plain install links the system's libode; CI's portable check sets PSA_ESP_REQUIRE_PORTABLE=1",
)


@portable
def test_the_extension_carries_its_libode():
    extension = Path(psa_esp._native.__file__)
    linked = subprocess.run(["ldd", str(extension)], capture_output=True, text=True, check=True).stdout
    ode = [line for line in linked.splitlines() if "libode" in line]
    assert ode, linked
    bundled = (extension.parents[1] / "psa_esp.libs").resolve()
    for line in ode:
        path = Path(line.split("=>")[1].split("(")[0].strip()).resolve()
        assert path.parent == bundled, f"libode comes from outside the wheel: {line}"


@portable
def test_the_wheel_is_one_for_cpython_3_9_on_and_glibc_2_28_on():
    tags = [line.split(":", 1)[1].strip() for line in metadata.distribution("psa-esp").read_text("WHEEL").splitlines() if line.startswith("Tag:")]
    assert tags == ["cp39-abi3-manylinux_2_28_x86_64"], tags


@portable
def test_the_wheel_renders_with_its_own_font():
    # CI runs this with the system's fonts hidden (.ci/run checks that they are).
    assert (Path(psa_esp.__file__).with_name("fonts") / "DejaVuSans.ttf").is_file()
    env = psa_esp.env.PsaEnv(1, render_mode="rgb_array")
    env.reset(seed=1)
    frame = env.render()
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.std() > 0


def test_the_ode_backend_flies_the_command_lines_trajectory_bit_for_bit(cli, champions, tmp_path):
    """The Python ODE world (in the portable wheel: the wheel's copy of
    libode) against `psa-esp replay` on the system's libode, state by state."""
    network = psa_esp.Network(champions[1], 1)
    path = tmp_path / "champion.json"
    network.save(path)
    cli("replay", path, "--backend", "ode", "--out", tmp_path / "replay")
    with open(tmp_path / "replay" / "trajectory.csv", newline="") as file:
        rows = list(csv.DictReader(file))
    trial = psa_esp.Trial(1, backend="ode")
    observation = trial.reset(1)
    flown = [trial.state]
    while not trial.done:
        observation, _ = trial.step(network.activate(observation))
        flown.append(trial.state)
    columns = ["x", "y", "heading", "vx", "vy", "omega"]
    expected = [[float(row[c]) for c in columns] for row in rows]
    assert len(flown) == len(expected)
    assert np.array_equal(np.array(flown), np.array(expected))

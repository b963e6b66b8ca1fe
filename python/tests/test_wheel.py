"""The installed package is portable: its extension finds libode inside
the wheel (auditwheel's repair), not on the system. CI installs the
repaired wheel and sets PSA_ESP_REQUIRE_PORTABLE=1; an editable or
plain install (pip install ./python) links the system's libode."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

import psa_esp._native


def test_the_extension_carries_its_libode():
    if not os.environ.get("PSA_ESP_REQUIRE_PORTABLE"):
        pytest.skip("a plain install links the system's libode; CI's portable check sets PSA_ESP_REQUIRE_PORTABLE=1")
    extension = Path(psa_esp._native.__file__)
    linked = subprocess.run(["ldd", str(extension)], capture_output=True, text=True, check=True).stdout
    ode = [line for line in linked.splitlines() if "libode" in line]
    assert ode, linked
    bundled = (extension.parents[1] / "psa_esp.libs").resolve()
    for line in ode:
        path = Path(line.split("=>")[1].split("(")[0].strip()).resolve()
        assert path.parent == bundled, f"libode comes from outside the wheel: {line}"

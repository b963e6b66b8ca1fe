"""The report's Welch t-test from Python: Wikipedia's first example (its
values from the Welch-Satterthwaite formula), symmetry, and the
degenerate samples."""

from __future__ import annotations

import math

import numpy as np

import psa_esp

A1 = [27.5, 21.0, 19.0, 23.6, 17.0, 17.9, 16.9, 20.1, 21.9, 22.6, 23.1, 19.6, 19.0, 21.7, 21.4]
A2 = [27.1, 22.0, 20.8, 23.4, 23.4, 23.5, 25.8, 22.0, 24.8, 20.2, 21.9, 22.1, 22.9, 20.5, 24.4]


def test_welch_gives_the_textbook_values_either_way_round():
    t, df, p = psa_esp.welch(A1, A2)
    assert math.isclose(t, -2.455356398286006, rel_tol=1e-10)
    assert math.isclose(df, 24.988529290231416, rel_tol=1e-10)
    assert math.isclose(p, 0.021378001462866992, rel_tol=1e-8)
    t2, df2, p2 = psa_esp.welch(np.array(A2), np.array(A1))
    assert (t2, df2, p2) == (-t, df, p)


def test_welch_of_too_few_values_is_nan_and_of_equal_constants_is_p_1():
    assert all(math.isnan(x) for x in psa_esp.welch([1.0], A2))
    t, _, p = psa_esp.welch([3.0, 3.0], [3.0, 3.0, 3.0])
    assert (t, p) == (0.0, 1.0)

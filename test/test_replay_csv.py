# SPDX-License-Identifier: Apache-2.0
"""The vectorised CSV formatter writes what printf's %.Nf writes."""

from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
from satmotor_ros.cli._fastcsv import fixed_point, rows, text


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(min_value=-1e6, max_value=1e6, allow_nan=False), min_size=1,
                max_size=20), st.integers(min_value=0, max_value=12))
def test_fixed_point_equals_printf(values, decimals):
    lines = rows([fixed_point(np.array(values), decimals)]).decode().splitlines()
    biggest = max(abs(v) for v in values)
    for got, value in zip(lines, values):
        used = len(got.split('.')[1]) if '.' in got else 0
        # as many decimals as asked, unless value * 10^decimals would pass 2^53
        assert used == decimals or (used < decimals and biggest * 10.0 ** decimals >= 2**53)
        want = f'{value:.{used}f}'
        if want.startswith('-') and float(want) == 0.0:
            want = want[1:]  # printf keeps the sign of a value rounded to zero; we do not
        # printf rounds the exact decimal expansion, we the binary product: at most the
        # last digit differs
        assert got == want or abs(float(got) - value) <= 1.01 * 10.0 ** -used, (got, want)


def test_nan_is_empty_and_integers_are_exact():
    out = rows([fixed_point(np.array([1.0, np.nan, np.inf]), 3),
                fixed_point(np.array([1_700_000_000_123_456_789, -5, 0], dtype=np.int64), 0),
                text(['OK', 'ERROR', ''])])
    assert out == b'1.000,1700000000123456789,OK\n,-5,ERROR\n,0,\n'


def test_too_large_values_lose_decimals_not_digits():
    assert rows([fixed_point(np.array([3.0e12, 1.0]), 9)]) == \
        b'3000000000000.000\n1.000\n'  # 3e15 < 2^53

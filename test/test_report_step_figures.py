# SPDX-License-Identifier: Apache-2.0
"""
A step's plain figures are the table's, or flagged (cold review of issue 20, finding 7).

On the 2021 MBARI log the second step read 'plain RMSE 1.323 -> 1.332 (must fall)' for the
valve-only model whose table gives 1.146: that step refits the valve under its own noise
weights and judges against the refit over its own rows.
"""

from types import SimpleNamespace

import numpy as np
from satmotor_ros.identify.report import _refitted
from satmotor_ros.model.effects import Effect
from satmotor_ros.model.units import LPM

VALVE = Effect('threshold:dp', 2e-10, 'dp', 19.868e6, direction='negative',
               options=(('exponent', 1.0),))


def _calibration(step_rmse, table_rmse, rows=10):
    """Return a calibration of one effect and two steps, the second's baseline at `step_rmse`."""
    error = np.full(rows, step_rmse * LPM)
    left_out = np.zeros(rows, dtype=bool)
    left_out[0] = True
    first = SimpleNamespace(baseline=SimpleNamespace(rmse=2.0 * LPM), left_out=left_out)
    second = SimpleNamespace(baseline=SimpleNamespace(rmse=step_rmse * LPM, cv_error=error),
                             left_out=left_out)
    found = (SimpleNamespace(),)
    return SimpleNamespace(
        forward=SimpleNamespace(steps=(first, second)), found=found,
        row_errors=lambda score: SimpleNamespace(rmse_lpm=table_rmse), over=None,
        inliers=~left_out, effects=lambda: (VALVE,))


def test_a_step_judged_against_a_refit_says_so_with_both_figures():
    note = _refitted(_calibration(1.323, 1.146), 2)
    assert "Not the table's figures" in note
    assert '1.323 l/min' in note and 'gives 1.146 l/min' in note and 'over its 9 rows' in note
    assert '`threshold:dp@negative cracking at 19.87 MPa`' in note


def test_a_step_whose_figures_are_the_table_s_and_the_first_step_say_nothing_more():
    assert _refitted(_calibration(1.146, 1.146), 2) == ''
    assert _refitted(_calibration(1.1465, 1.146), 2) == ''  # the table's rounding
    assert _refitted(_calibration(1.323, 1.146), 1) == ''

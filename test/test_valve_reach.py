# SPDX-License-Identifier: Apache-2.0
"""
A valve's flow at full drop is told honestly (cold review of issue 20, finding 6).

The README gave the law at the rows' highest drop (7.3 l/min at 20.20 MPa) while the samples
reach 21.57 MPa, where the law gives 41.9 l/min, more than the 21-22 l/min measured there.
"""

import numpy as np
import pytest
from satmotor_ros.identify.valve_reach import full_drop, says
from satmotor_ros.model.effects import Effect
from satmotor_ros.model.units import LPM, MPA

# 1 l/min per MPa above 20 MPa, on the negative side; fitted on |dp| up to 20.2 MPa
VALVE = Effect('threshold:dp', LPM / MPA, 'dp', 20.0 * MPA, direction='negative',
               options=(('exponent', 1.0),), fitted_range=(('dp', 0.0, 20.2 * MPA),))


def test_the_law_at_the_rows_top_and_at_the_samples_top_with_the_flow_measured_there():
    rows = np.array([-20.2, -19.0, 5.0, 11.9]) * MPA  # the positive side's drops do not count
    dp = np.array([-21.6, -21.0, -20.5, -10.0, 30.0]) * MPA
    flow = np.array([0.5, 22.0, 0.1, 3.0, 40.0]) * LPM
    reach = full_drop(VALVE, rows, dp, flow)
    assert reach['fitted_dp_mpa'] == pytest.approx(20.2)
    assert reach['fitted_flow_lpm'] == pytest.approx(0.2)
    assert reach['data_dp_mpa'] == pytest.approx(21.6)  # not the positive side's 30 MPa
    assert reach['flow_lpm'] == pytest.approx(1.6)
    assert reach['measured_flow_lpm'] == pytest.approx(0.5)
    assert reach['extrapolated']  # 21.6 > 20.2 + 5 % of the span
    # more than measured at -21.6 (1.6 > 0.5) and -20.5 (0.5 > 0.1), not at -21.0
    assert reach['above_measured'] == 2 and reach['above_measured_from_mpa'] == pytest.approx(20.5)
    text = says({'name': 'threshold:dp@negative cracking at 20 MPa', 'full_drop': reach})
    assert '0.2 l/min at the highest drop of the rows' in text and '(20.2 MPa)' in text
    assert 'gives 1.6 l/min where 0.5 l/min were measured' in text and 'extrapolated' in text
    assert 'At 2 sample(s)' in text and 'from 20.5 MPa' in text


def test_a_law_within_the_measured_flow_and_the_fitted_range_is_not_flagged():
    rows = np.array([-20.2, -19.0]) * MPA
    dp = np.array([-20.9, -20.5]) * MPA
    flow = np.array([22.0, 21.0]) * LPM
    reach = full_drop(VALVE, rows, dp, flow)
    assert not reach['extrapolated'] and reach['above_measured'] == 0
    assert reach['above_measured_from_mpa'] is None
    text = says({'name': 'v', 'full_drop': reach})
    assert 'extrapolated' not in text and 'more than the whole' not in text
    assert full_drop(VALVE, rows, np.array([1.0]) * MPA, np.array([1.0])) == {}  # none its side
    assert says({'name': 'v'}) == ''

# SPDX-License-Identifier: Apache-2.0
"""The report's plots: nothing cut at the figure's edge, signed data shown signed."""

from matplotlib.image import imread
import numpy as np
import pytest

from satmotor_ros.identify import calibrate
from satmotor_ros.identify.report import (channel_axes, plot_residual_grid, QUADRANT_MARKERS,
                                          quadrants, write_report)
from satmotor_ros.identify.synthetic import generate, Injection, Plan
from satmotor_ros.model.units import LPM, RPM

LONG = 'motor_housing_case_drain_temperature_sensor_number_two_backup_channel'


def _edges_blank(path):
    """Return whether the outermost pixel columns of a PNG are all white (nothing cut there)."""
    rgb = imread(path)[:, :, :3]
    return bool(np.all(rgb[:, :2] > 0.99) and np.all(rgb[:, -2:] > 0.99))


@pytest.fixture(scope='module')
def signed(tmp_path_factory):
    """Calibrate on four quadrants, with a channel of a long name; write the report."""
    plan = Plan(liquid='oil', reverse_share=0.3, pump_share=0.3, extra_channels=('aux', LONG))
    table = generate(plan, Injection.realistic('external_leakage', 1, 'oil'), seed=3)
    cal = calibrate(table, 'oil')
    out = tmp_path_factory.mktemp('signed')
    write_report(cal, out, cal.summary())
    return cal, out


def test_a_long_legend_stays_inside_the_residual_grid(tmp_path):
    x = np.linspace(0.0, 1.0, 20)
    residuals = {'before (no effect)': 0.01 * LPM * x,
                 'after external_leakage(p_case) + clearance_wear(time)': 0.0 * x,
                 'after external_leakage(p_case) + clearance_wear(time) + term:dp^1.6*n^0.94':
                 0.0 * x}
    plot_residual_grid({'n [rpm]': x, 'dp [MPa]': x}, residuals, 'title', tmp_path / 'r.png')
    assert _edges_blank(tmp_path / 'r.png')


def test_no_plot_is_cut_at_its_edges(signed):
    _, out = signed
    for name in ('residual_map', 'residuals', 'characteristics', 'ranking'):  # ranking: long name
        assert _edges_blank(out / f'{name}.png'), name


def test_signed_data_are_plotted_against_signed_speed_drop_and_flow(signed):
    cal, _ = signed
    axes = channel_axes(cal.parts, cal.table)
    assert np.array_equal(axes['n [rpm]'], cal.table.speed / RPM)
    assert np.array_equal(axes['flow [l/min]'], cal.table.flow / LPM)
    assert min(axes['n [rpm]']) < 0 < max(axes['n [rpm]'])
    assert min(axes['dp [MPa]']) < 0 < max(axes['dp [MPa]'])


def test_each_point_is_named_by_its_quadrant(signed):
    cal, _ = signed
    n, dp = cal.table.speed, cal.table.dp
    expected = np.where(n * dp < 0, 'pump', 'motor')
    expected = np.char.add(expected, np.where(n < 0, ', reverse', ', forward'))
    assert np.array_equal(quadrants(cal.parts), expected)
    assert set(expected) == set(QUADRANT_MARKERS)

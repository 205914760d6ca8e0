# SPDX-License-Identifier: Apache-2.0
"""Plots no outlier can squash, with outliers and EXTRAPOLATED points marked, units true."""

from dataclasses import replace

from matplotlib.image import imread
import numpy as np
import pytest

from satmotor_ros.identify import calibrate
from satmotor_ros.identify.plot_tools import (BEFORE_COLOR, residual_colors, robust_limits,
                                              unique_legend)
from satmotor_ros.identify.report import channel_axes, plot_residual_grid, pyplot
from satmotor_ros.identify.synthetic import generate, Injection, Plan
from satmotor_ros.model.units import LPM, RPM


def _red_pixels(path):
    rgb = imread(path)[:, :, :3]
    return int(np.sum((rgb[:, :, 0] > 0.9) & (rgb[:, :, 1] < 0.2) & (rgb[:, :, 2] < 0.2)))


def test_one_outlier_does_not_set_the_axis():
    rng = np.random.default_rng(1)
    y = rng.normal(0.0, 0.02, 200)
    lo, hi = robust_limits(np.append(y, 4.0))
    assert hi < 0.5 and lo < 0.0 < hi
    assert lo <= y.min() and hi >= y.max()  # the others all inside
    lo, hi = robust_limits(y + 1.0)
    assert lo < 0.0  # the zero line stays on the axis
    assert robust_limits(np.array([np.nan, np.inf])) == (-1.0, 1.0)


def test_the_point_beyond_the_axis_is_drawn_and_counted(tmp_path, monkeypatch):
    texts = []
    plt = pyplot()
    original = plt.Axes.text

    def spy(self, *args, **kwargs):
        texts.append(args[2] if len(args) > 2 else '')
        return original(self, *args, **kwargs)
    monkeypatch.setattr(plt.Axes, 'text', spy)
    x = np.linspace(0.0, 1.0, 50)
    residual = np.random.default_rng(2).normal(0.0, 0.01, 50) * LPM
    residual[7] = 5.0 * LPM
    plot_residual_grid({'n [rpm]': x}, {'model': residual}, 'title', tmp_path / 'r.png')
    assert texts == ['1 beyond the axis (drawn at its edge)']


def test_marked_points_are_ringed(tmp_path):
    x = np.linspace(0.0, 1.0, 30)
    residual = np.random.default_rng(3).normal(0.0, 0.01, 30) * LPM
    plot_residual_grid({'n [rpm]': x}, {'model': residual}, 't', tmp_path / 'plain.png')
    mask = np.zeros(30, dtype=bool)
    mask[[3, 17]] = True
    plot_residual_grid({'n [rpm]': x}, {'model': residual}, 't', tmp_path / 'marked.png',
                       {'flagged EXTRAPOLATED': mask})
    assert _red_pixels(tmp_path / 'plain.png') == 0 < _red_pixels(tmp_path / 'marked.png')


def test_before_is_grey_under_a_coloured_after():
    assert residual_colors(1) == ['C0']
    assert residual_colors(3) == [BEFORE_COLOR, 'C0', 'C1']


def test_a_legend_names_each_label_once():
    plt = pyplot()
    fig, ax = plt.subplots()
    for _ in range(3):
        ax.plot([0, 1], [0, 1], 'o', color='C0', label='measured, |n| ~ 0 rpm')
    ax.plot([0, 1], [1, 0], label='other')
    unique_legend(ax)
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        'measured, |n| ~ 0 rpm', 'other']
    plt.close(fig)


def test_an_axis_is_labelled_with_its_true_unit_or_says_it_is_unknown():
    table = generate(Plan(liquid='oil', extra_channels=('aux',)), Injection(), seed=1)
    cal = calibrate(table, 'oil')
    n = len(cal.table)
    channels = {**cal.table.channels, 'speed_setpoint': np.full(n, 100.0),
                'mystery': np.ones(n)}
    units = {k: v for k, v in cal.table.units.items() if k != 'mystery'}
    axes = channel_axes(cal.parts, replace(cal.table, channels=channels, units=units))
    assert np.allclose(axes['speed_setpoint [rpm]'], 100.0 / RPM)
    assert 'mystery [?]' in axes and 'mystery [-]' not in axes


@pytest.fixture(scope='module')
def outlier_report(tmp_path_factory):
    """Calibrate a table with one gross outlier and write its report."""
    from satmotor_ros.identify.report import write_report
    table = generate(Plan(liquid='water'), Injection.realistic('external_leakage', 1.0, 'water'),
                     seed=4)
    flow = table.flow.copy()
    flow[17] += 3.0 * LPM
    cal = calibrate(replace(table, flow=flow), 'water')
    out = tmp_path_factory.mktemp('outlier')
    write_report(cal, out, cal.summary())
    return cal, out


def test_the_calibration_plots_ring_the_outlier(outlier_report):
    cal, out = outlier_report
    assert cal.forward.outliers.any()
    for name in ('residuals.png', 'characteristics.png'):
        assert _red_pixels(out / name) > 0, name


def test_a_report_shows_no_directory_of_this_machine(tmp_path, monkeypatch):
    from satmotor_ros.cli import main
    from satmotor_ros.identify.plot_tools import portable
    from vendored_data import data_path
    log = data_path('real', 'mbari_pto', 'FrictionIDMovesWithBiasCurr.exp')
    monkeypatch.chdir(tmp_path)
    assert main(['validate', str(log.resolve()), '--columns', 'mbari_pto', '--liquid', 'oil',
                 '--displacement', '0.30 in^3/rev', '--out', 'val']) == 0
    report = (tmp_path / 'val' / 'report.md').read_text()
    assert 'Data: `FrictionIDMovesWithBiasCurr.exp`' in report
    assert 'columns mapped by mbari_pto (packaged)' in report
    before_json = report[:report.index('## validation.json')]
    assert str(tmp_path) not in before_json and str(log.parent) not in before_json
    assert portable('rel/x.csv') == 'rel/x.csv'
    assert portable(str(tmp_path / 'a' / 'b.csv')) == 'a/b.csv'


def test_the_demo_prediction_residual_axis_shows_the_steady_bias_not_the_spikes():
    from satmotor_ros.cli._demo_report import _residual_limits, RESIDUAL_FLOOR
    residual = np.full(1000, -0.55)
    residual[::100] = 500.0  # the transient at each step
    quiet = residual < 1.0
    lo, hi = _residual_limits(residual, quiet)
    assert lo < -0.55 < 0.0 < hi and hi == pytest.approx(max(RESIDUAL_FLOOR, 5.5))
    small = np.linspace(-0.3, 0.2, 50)
    lo, hi = _residual_limits(small, np.ones(50, dtype=bool))
    assert lo <= -0.3 and hi >= 0.2 and hi < 1.0  # nothing cut: the whole range

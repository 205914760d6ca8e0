# SPDX-License-Identifier: Apache-2.0
"""Calibration from every sample of a transient recording: the model plus lines and sensor lags."""

from dataclasses import replace
import json

import numpy as np
import pytest

from satmotor_ros.cli import main
from satmotor_ros.identify import calibrate, IdentificationError, Options
from satmotor_ros.identify.candidates import build_library
from satmotor_ros.identify.coverage import COVERED, MOST
from satmotor_ros.identify.fit import LossFit
from satmotor_ros.identify.pipeline import read_rows
from satmotor_ros.identify.selection import CrossValidatedSelector
from satmotor_ros.identify.synthetic import (Dynamics, first_order, generate_series,
                                             generate_transient, Injection, Plan,
                                             REALISTIC_DYNAMICS, to_columns, write_bag_of)
from satmotor_ros.identify.table import write_csv
from satmotor_ros.identify.transient import (bin_means, bins, segments, sparse_bin_means,
                                             transient_samples, variance_inflation)
from satmotor_ros.identify.validate import validate
from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, MPA
from satmotor_ros.model.viscosity import standard_law


def _recording(liquid, effect='none', dynamics=REALISTIC_DYNAMICS, seed=0, **kw):
    return generate_transient(Plan(liquid=liquid), Injection.realistic(effect, 1.0, liquid),
                              dynamics, seed=seed, **kw)


def _dynamics(cal):
    return {d['term']: d for d in cal.summary()['dynamics']}


def _covers(d, truth):
    """
    Tell whether the interval holds the truth, give or take 2 % of it or 1 ms of a lag.

    A bin's change carries its end values' noise, which shrinks the lags by up to about a
    millisecond here (errors in variables), and the generator's 2 ms steps add a little.
    """
    lo, hi = d['ci95']
    slack = max(0.02 * abs(truth), 1e-3 if d['unit'] == 's' else 1e-14)
    return lo - slack < truth < hi + slack


def test_bin_means_are_trapezoid_means_and_a_derivative_mean_is_the_change():
    rng = np.random.default_rng(1)
    time = np.cumsum(rng.uniform(0.005, 0.015, 200))  # uneven steps
    x = np.sin(3 * time) + rng.normal(0, 0.1, time.size)
    first, _ = segments(time, 3.0)
    a, b = bins(np.ones(time.size, dtype=bool), first, 7)
    assert np.all(b > a) and np.all(a[1:] == b[:-1])  # neighbours share one sample
    for lo, hi, m in zip(a, b, bin_means(time, x, a, b)):
        assert m == pytest.approx(np.trapezoid(x[lo:hi + 1], time[lo:hi + 1])
                                  / (time[hi] - time[lo]))
    # d/dt of the piecewise-linear x, averaged over a bin, is the change across it
    rate = np.repeat(np.diff(x) / np.diff(time), 2)
    t2 = np.repeat(time, 2)[1:-1]
    for lo, hi in zip(a, b):
        inside = (t2 >= time[lo]) & (t2 <= time[hi])
        assert np.trapezoid(rate[inside], t2[inside]) == pytest.approx(x[hi] - x[lo])


def test_sparse_bin_means_are_the_bin_means_bit_for_bit():
    rng = np.random.default_rng(2)
    time = np.cumsum(rng.uniform(0.005, 0.015, 3000))
    usable = rng.uniform(size=time.size) > 0.01
    first, _ = segments(time, 3.0)
    a, b = bins(usable, first, 9)
    unknown = ~usable | (rng.uniform(size=time.size) < 0.003)  # NaN bins, as bin_means
    means = sparse_bin_means(time, unknown, a, b)
    for share in (0.05, 0.5, 0.0):
        x = np.where(rng.uniform(size=time.size) < share, rng.normal(0, 1, time.size), 0.0)
        if share:
            x[[0, 1, 700, 701, time.size - 1]] = (1.5, -2.0, 3.0, 0.25, 0.5)  # ends, neighbours
        x[unknown] = np.nan
        at = rng.permutation(np.flatnonzero(np.nan_to_num(x) != 0.0))  # in any order
        dense = bin_means(time, x, a, b)
        assert np.isnan(dense).any() and (np.nan_to_num(dense) != 0.0).sum() >= (50 if share
                                                                                 else 0)
        np.testing.assert_array_equal(means(at, x[at]), dense)  # NaN where dense is


def test_bins_never_span_a_gap_or_an_unusable_sample():
    time = np.concatenate((np.arange(100) * 0.01, 5.0 + np.arange(50) * 0.01))
    usable = np.ones(time.size, dtype=bool)
    usable[40] = False
    first, step = segments(time, 3.0)
    assert step == pytest.approx(0.01) and np.flatnonzero(first).tolist() == [0, 100]
    a, b = bins(usable, first, 10)
    for lo, hi in zip(a, b):
        assert usable[lo:hi + 1].all()
        assert not first[lo + 1:hi + 1].any()
        assert 10 <= hi - lo < 20  # a run's remainder joins its last bin
    x = np.where(usable, 1.0, np.nan)
    assert np.all(np.isfinite(bin_means(time, x, a, b)))


def test_first_order_lag_is_exact_for_a_ramp_and_starts_at_rest():
    t = np.arange(0.0, 1.0, 1e-3)
    assert np.allclose(first_order(t, 1e-3, 0.05), t - 0.05 * (1 - np.exp(-t / 0.05)),
                       atol=1e-12)
    assert np.allclose(first_order(np.full(5, 3.0), 0.01, 0.1), 3.0, rtol=1e-14)


def test_variance_inflation_is_one_for_white_noise_and_large_for_correlated_noise():
    rng = np.random.default_rng(0)
    white = rng.normal(size=20000)
    assert variance_inflation(white) < 1.05
    correlated = first_order(rng.normal(size=20000), 1.0, 20.0)  # AR(1), ~20-sample memory
    assert variance_inflation(correlated) == pytest.approx(40.0, rel=0.25)


def _binned_gaussian_noise(rng, rows, width, size):
    """Return white noise through a Gaussian kernel `width` samples wide, in means of `size`."""
    reach = int(np.ceil(4 * width))
    kernel = np.exp(-0.5 * (np.arange(-reach, reach + 1) / width) ** 2)
    x = np.convolve(rng.normal(size=rows * size + 2 * reach), kernel, 'valid')
    return x.reshape(rows, size).mean(axis=1)


def test_variance_inflation_matches_the_truth_on_noise_like_the_mbari_logs():
    # the logs' noise: a Gaussian autocorrelation exp(-t^2 / (4 s^2)), s = 0.12 s, at 25 Hz,
    # in rows of 0.2 s (5 samples): N / inflation rows carry the information
    width, size, rows = 3.0, 5, 850
    lags = np.arange(-400, 401)
    inner = np.arange(-size + 1, size)
    truth = (size * np.sum(np.exp(-lags ** 2 / (4 * width ** 2)))
             / np.sum((size - np.abs(inner)) * np.exp(-inner ** 2 / (4 * width ** 2))))
    assert truth == pytest.approx(2.36, abs=0.01)
    rng = np.random.default_rng(3)
    found = np.array([variance_inflation(_binned_gaussian_noise(rng, rows, width, size))
                      for _ in range(40)])
    assert np.mean(found) == pytest.approx(truth, rel=0.08)
    # steady from one recording to the next (batch means: 1.1-3.5, sd 0.75)
    assert np.std(found) < 0.3 and np.min(found) > 0.75 * truth


@pytest.mark.slow
@pytest.mark.parametrize('effect', ['external_leakage', 'viscosity_temperature',
                                    'clearance_wear', 'flow_sensor_offset', 'term:dp^2*n',
                                    'channel:aux'])
def test_a_recording_with_too_few_steady_windows_is_calibrated_from_every_sample(effect):
    liquid = 'oil' if effect in ('term:dp^2*n', 'flow_sensor_offset') else 'water'
    table = _recording(liquid, effect, seed=1)
    cal = calibrate(table, liquid)
    assert cal.mode == 'transient' and 'steady windows' in cal.mode_reason
    assert cal.samples is not None and cal.samples.n_samples == len(table)
    runner = cal.selection.runner_up
    named = [cal.summary()['effect'], runner.effect if runner else '']
    assert any(n == effect or (effect.startswith('term:') and n.startswith('term:'))
               for n in named)
    assert cal.error_after.rmse_lpm < cal.error_before.rmse_lpm


def test_dynamic_parameters_are_recovered_within_their_intervals():
    truth = {'line_compliance': 5e-13, 'speed_lag': 0.02, 'flow_lag': 0.05}
    cal = calibrate(_recording('water', seed=2), 'water')
    found = _dynamics(cal)
    for term, value in truth.items():
        lo, hi = found[term]['ci95']
        assert _covers(found[term], value), (term, found[term])
        assert found[term]['nonzero']
        assert hi - lo < 0.2 * value  # and the interval says something
    assert 'tau_n - tau_Q' in found['speed_lag']['note']


@pytest.mark.parametrize('term', ['line_compliance', 'line_compliance_b', 'speed_lag',
                                  'flow_lag'])
def test_one_dynamic_term_alone_is_found_and_the_others_are_not(term):
    dynamics = replace(Dynamics(), **{term: getattr(REALISTIC_DYNAMICS, term) or 5e-13})
    cal = calibrate(_recording('oil', dynamics=dynamics, seed=3), 'oil', options=Options(
        mode='transient'))
    for name, d in _dynamics(cal).items():
        if name == term:
            assert _covers(d, getattr(dynamics, term)) and d['nonzero'], d
        elif 'left_out' not in d:  # a line volume the loss does not show is left out
            assert _covers(d, 0.0), (name, d)
        else:
            assert name in ('line_compliance', 'line_compliance_b'), (name, d)


def test_a_line_volume_on_each_port_is_recovered_beside_the_lags():
    dynamics = replace(REALISTIC_DYNAMICS, line_compliance_b=3e-13)
    found = _dynamics(calibrate(_recording('oil', dynamics=dynamics, seed=7), 'oil',
                                options=Options(mode='transient')))
    for term in ('line_compliance', 'line_compliance_b', 'speed_lag', 'flow_lag'):
        assert _covers(found[term], getattr(dynamics, term)) and found[term]['nonzero'], term


def test_validate_applies_a_calibrated_line_volume_the_data_do_not_show():
    table = _recording('oil', dynamics=REALISTIC_DYNAMICS, seed=7)  # port A's volume only
    volumes = {'line_compliance': 5e-13, 'line_compliance_b': 3e-13}
    checked = validate(table, MotorModel.default('oil'), 'oil', 'transient', dynamics=volumes)
    assert checked.transient['applied'] == volumes


@pytest.mark.parametrize('seed', [4, 5, 6])
def test_clean_transient_recording_says_none(seed):
    cal = calibrate(_recording('water', seed=seed), 'water')
    assert cal.mode == 'transient'
    assert cal.summary()['effect'] == 'none', cal.selection.verdict


def test_correlated_residuals_do_not_make_a_random_channel_significant():
    """A slow flowmeter drift and an unrelated slow channel: the naive F-test bites."""
    liquid = 'water'
    table = _recording(liquid, seed=7, duration_s=120.0)
    rng = np.random.default_rng(7)
    n = len(table)
    drift = first_order(rng.normal(size=n), 0.01, 8.0) * 0.6 * LPM
    channel = first_order(rng.normal(size=n), 0.01, 8.0)
    table = replace(table, flow=table.flow + drift,
                    channels={**table.channels, 'aux': channel})
    model = MotorModel.default(liquid)
    samples = transient_samples(model, table)
    channels = {**samples.table.channels, 'p_out': samples.table.p_out}
    candidates, _ = build_library(samples.parts, channels, standard_law(model.liquid, liquid))
    aux = next(c for c in candidates if c.effect == 'channel:aux')
    parts = samples.parts
    index = np.arange(len(parts))
    sigma = np.full(len(parts), np.std(parts.flow - LossFit().fit(parts).predict(parts)))
    p = {}
    for correlated in (False, True):
        selector = CrossValidatedSelector(time_ordered=True, guard=1, correlated=correlated)
        base = selector.score(parts, (), sigma, index)
        p[correlated] = selector.score(parts, (aux,), sigma, index, baseline=base).p_value
    assert p[False] < 1e-5  # ignoring the correlation, chance looks like an effect
    assert p[True] > 0.05 / len(candidates)
    assert calibrate(table, liquid).summary()['effect'] == 'none'


def test_gaps_missing_rows_and_uneven_steps_are_handled():
    table = _recording('oil', seed=8)
    time = table.channels['time']
    keep = ~((time > 30.0) & (time < 32.0))  # a 2 s gap
    keep[::97] = False  # single missing rows
    table = table.select(keep)
    rng = np.random.default_rng(8)
    jitter = table.channels['time'] + rng.uniform(-2e-3, 2e-3, len(table))
    table = replace(table, channels={**table.channels, 'time': np.sort(jitter)})
    cal = calibrate(table, 'oil')
    assert cal.mode == 'transient' and cal.samples.segments == 2
    assert '2 stretch(es)' in cal.table.notes[-1]
    for term, d in _dynamics(cal).items():
        if term == 'line_compliance_b':  # no volume on port B's line: the screen leaves it out
            assert 'left_out' in d
        else:
            assert _covers(d, getattr(REALISTIC_DYNAMICS, term)), (term, d)


def test_one_speed_only_is_refused_saying_what_cannot_be_told_apart():
    plan = Plan(liquid='oil', speed_rpm=(800.0, 800.0))
    table = generate_transient(plan, Injection(), REALISTIC_DYNAMICS, seed=9, duration_s=60.0)
    with pytest.raises(IdentificationError, match='one speed only.*C_id'):
        calibrate(table, 'oil')


def test_auto_keeps_steady_windows_when_they_hold_most_samples_and_the_envelope():
    table = generate_series(Plan(liquid='oil'), Injection(), seed=2, samples=30000)
    cal = calibrate(table, 'oil')
    assert cal.mode == 'series' and cal.samples is None
    summary = cal.summary()
    assert summary['mode'] == 'series' and 'span' in summary['mode_reason']
    coverage = summary['coverage']
    assert coverage['fraction'] >= MOST and coverage['envelope_share'] >= COVERED
    assert coverage['samples_total'] == len(table)


def test_auto_uses_every_sample_when_the_windows_miss_part_of_the_envelope():
    # plateaus at low drop, then a stretch of fast moves that reach the top of the drop:
    # the windows hold most samples but not the envelope, so every sample is used
    table = generate_series(Plan(liquid='oil'), Injection(), seed=2, samples=30000)
    dp = table.p_in - table.p_out
    fast = np.arange(len(table)) > 0.8 * len(table)
    wave = 0.6 + 0.4 * np.sin(np.arange(len(table)) / 7.0)
    p_in = np.where(fast, table.p_out + wave * 1.3 * float(np.max(dp)), table.p_in)
    steady = read_rows(MotorModel.default('oil'), table, Options())
    assert steady.mode == 'series'
    read = read_rows(MotorModel.default('oil'), replace(table, p_in=p_in), Options())
    assert read.mode == 'transient', read.reason
    assert 'of its operating envelope' in read.reason and 'every sample' in read.reason
    assert read.coverage['samples_used'] > 0.9 * len(table)
    assert read.coverage['envelope']['positive']['dp_mpa'][1] > 1.2 * float(np.max(dp)) / MPA


@pytest.mark.slow
def test_transient_bag_through_satmotor_calibrate(tmp_path, capsys):
    table = _recording('water', 'external_leakage', seed=10, duration_s=75.0)
    write_bag_of(tmp_path / 'bag', table, 'mcap')
    code = main(['calibrate', str(tmp_path / 'bag'), '--liquid', 'water', '--out',
                 str(tmp_path / 'out')])
    out = capsys.readouterr()
    assert code == 0, out.err
    assert 'mode transient' in out.out
    result = json.loads((tmp_path / 'out' / 'calibration.json').read_text())
    assert result['effect'] == 'external_leakage'
    assert result['mode'] == 'transient' and result['n_samples'] == len(table)
    assert 'steady windows' in result['mode_reason']
    terms = {d['term']: d for d in result['dynamics']}
    assert set(terms) == {'line_compliance', 'line_compliance_b', 'speed_lag', 'flow_lag'}
    lo, hi = terms['line_compliance']['ci95']
    assert terms['line_compliance']['unit'] == 'm^3/Pa' and lo < 5e-13 < hi
    # the rig meters port A's line only: port B's volume is screened out, and says why
    assert 'coefficient' not in terms['line_compliance_b']
    assert 'the loss does not show it' in terms['line_compliance_b']['left_out']
    report = (tmp_path / 'out' / 'report.md').read_text()
    assert '## Transient terms' in report and 'Mode `transient`' in report


@pytest.mark.slow
def test_validate_reads_a_transient_recording_as_calibrate_does(tmp_path, capsys):
    table = _recording('water', 'external_leakage', seed=11, duration_s=60.0)
    data = tmp_path / 'run.csv'
    write_csv(data, to_columns(table))
    assert main(['calibrate', str(data), '--liquid', 'water', '--out', str(tmp_path / 'c')]) == 0
    assert main(['validate', str(data), '--liquid', 'water', '--motor',
                 str(tmp_path / 'c' / 'coefficients.yaml'), '--out', str(tmp_path / 'v')]) == 0
    capsys.readouterr()
    cal = json.loads((tmp_path / 'c' / 'calibration.json').read_text())
    val = json.loads((tmp_path / 'v' / 'validation.json').read_text())
    assert cal['mode'] == 'transient'
    assert val['n_points'] + val['n_flagged'] >= cal['n_points'] - len(cal['outliers'])
    # the model as calibrated, the bench's transient terms refitted: the in-sample error
    assert val['error']['rmse_lpm'] < 1.2 * cal['error_after']['rmse_lpm']


def test_a_valve_candidate_at_the_samples_above_its_crack_is_the_one_at_every_sample():
    from satmotor_ros.identify.pipeline import _sampled
    from satmotor_ros.model.effects import CandidateData
    from satmotor_ros.model.effects.threshold import KIND
    rec = _recording('water', 'external_leakage', duration_s=40.0)
    model = MotorModel.default('water')
    rows = read_rows(model, rec, Options(mode='transient'))
    sampled = _sampled(rows.samples)
    data = CandidateData(rows.parts, {}, standard_law(model.liquid, 'water'), frozenset(), '',
                         sampled)
    dense = data._replace(samples=sampled._replace(sparse=None))
    fast, _ = KIND.candidates(data)
    assert fast
    for i, f in enumerate(fast):
        low, span = f.shape[0].to_unit
        for v, e in ((0.0, 1.0), (0.5, 0.3), (0.5, 1.0), (0.97, 2.0), (0.5, 0.3)):
            x_c = low + span * v
            for k in (1.0, 2.5):  # the shape's flow reused for another coefficient
                got = f.modify(k * LPM, x_c, e).additive
                fresh = KIND.candidates(dense)[0][i]  # nothing kept from other calls
                np.testing.assert_array_equal(got, fresh.modify(k * LPM, x_c, e).additive)
        assert np.any(f.modify(LPM, low, 1.0).additive > 0.0)


def test_a_fitted_form_keeps_its_form_per_exponents_only():
    from satmotor_ros.model.effects import CandidateData
    from satmotor_ros.model.effects.term import KIND
    model = MotorModel.default('water')
    rows = read_rows(model, _recording('water', duration_s=20.0), Options(mode='transient'))
    data = CandidateData(rows.parts, {}, standard_law(model.liquid, 'water'), frozenset())
    kept, _ = KIND.candidates(data)
    for i, c in enumerate(kept):
        for theta in ((0.5, 2.0), (0.5, 1.0), (2.0, 1.0), (0.5, 2.0), (1.5, 0.7), (0.5, 1.0)):
            theta = theta[:len(c.shape)]
            for k in (1.0, 3.0):
                fresh = KIND.candidates(data)[0][i]
                np.testing.assert_array_equal(c.modify(k * LPM, *theta).additive,
                                              fresh.modify(k * LPM, *theta).additive)

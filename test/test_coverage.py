# SPDX-License-Identifier: Apache-2.0
"""Coverage: the envelope per direction, its share, and validate's samples outside it."""

from dataclasses import replace
import json

import numpy as np
import pytest

from satmotor_ros.cli import validate as validate_cli
from satmotor_ros.cli.calibrate import _errors
from satmotor_ros.identify import calibrate, write_csv
from satmotor_ros.identify.calibrated import Calibrated
from satmotor_ros.identify.candidates import build_library
from satmotor_ros.identify.columns import load_mapping, read_log
from satmotor_ros.identify.coverage import envelope, envelope_share, outside
from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.output import write_yaml
from satmotor_ros.identify.parts import loss_parts
from satmotor_ros.identify.synthetic import (generate, generate_transient, Injection, Plan,
                                             REALISTIC_DYNAMICS)
from satmotor_ros.identify.transient import (reading_spikes, segments, spikes,
                                             transient_samples)
from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, MPA, RPM
from satmotor_ros.model.viscosity import standard_law
from satmotor_ros.options import MotorOptions
from vendored_data import data_path
import yaml

MBARI = ('2021.07.26T10.51.44.exp', 'FrictionIDMovesWithBiasCurr.exp')


def test_the_envelope_is_given_per_direction_of_the_drop():
    dp = np.array([-20e6, -5e6, 2e6, 10e6])
    speed = np.array([-1000, -200, 100, 800]) * RPM
    env = envelope(dp, speed)
    assert env['negative']['dp_mpa'] == [-20.0, -5.0]
    assert env['negative']['speed_rpm'] == pytest.approx([-1000.0, -200.0])
    assert env['positive']['dp_mpa'] == [2.0, 10.0] and env['positive']['samples'] == 2
    # a sample beyond the top of one direction, or in a direction not calibrated, is outside
    flags = outside({'positive': env['positive']}, np.array([5e6, 12e6, -5e6]),
                    np.array([400, 400, -200]) * RPM)
    assert flags.tolist() == [False, True, True]


def test_the_share_of_the_envelope_is_the_least_span_covered_in_any_direction():
    rng = np.random.default_rng(0)
    dp = np.concatenate([rng.uniform(1e6, 20e6, 500), rng.uniform(-20e6, -1e6, 500)])
    speed = rng.uniform(100, 1500, 1000) * RPM * np.sign(dp)
    whole = envelope(dp, speed)
    low = np.abs(dp) < 10.5e6
    assert envelope_share(whole, whole, dp.size) == pytest.approx(1.0)
    assert envelope_share(envelope(dp[low], speed[low]), whole, dp.size) == pytest.approx(
        0.5, abs=0.05)
    one_side = dp > 0
    assert envelope_share(envelope(dp[one_side], speed[one_side]), whole, dp.size) == 0.0


def _csv(path, table):
    write_csv(path, {'time': ('s', table.channels['time']), 'speed': ('rpm', table.speed / RPM),
                     'flow': ('l/min', table.flow / LPM), 'p_in': ('MPa', table.p_in / MPA),
                     'p_out': ('MPa', table.p_out / MPA),
                     'temperature': ('degC', table.channels['temperature'])})
    return str(path)


def test_validate_gives_the_share_of_samples_outside_the_calibrated_envelope(tmp_path, capsys):
    narrow = generate(Plan(liquid='oil', dp_mpa=(2.0, 12.0), extra_channels=()), Injection(),
                      seed=4)
    wide = generate(Plan(liquid='oil', dp_mpa=(2.0, 22.0), extra_channels=()), Injection(),
                    seed=5)
    cal = calibrate(narrow, 'oil')
    write_yaml(cal, tmp_path / 'coefficients.yaml')
    written = yaml.safe_load((tmp_path / 'coefficients.yaml').read_text())
    assert written['coverage'] == cal.summary()['coverage']
    assert Calibrated(tmp_path / 'coefficients.yaml').envelope == written['coverage']['envelope']
    # every sample counts: on its own data, the few rows the calibration left out may be beyond
    for table, name, low, high in ((narrow, 'own', 0.0, 0.02), (wide, 'wide', 0.4, 0.6)):
        out = tmp_path / name
        code = validate_cli.command(_csv(tmp_path / f'{name}.csv', table), str(out), 'auto',
                                    MotorOptions('oil', str(tmp_path / 'coefficients.yaml')))
        assert code == 0, capsys.readouterr().err
        result = json.loads((out / 'validation.json').read_text())
        beyond = result['outside_calibrated_envelope']
        assert low <= beyond['share'] <= high and beyond['of'] == len(table)  # every sample
        assert result['coverage']['samples_used'] == result['n_points'] >= len(table) - 2
        report = (out / 'report.md').read_text()
        assert 'outside the envelope the model was calibrated on' in report
    assert 'outside the calibrated envelope' in capsys.readouterr().out


def test_a_motor_file_without_an_envelope_says_so_and_a_malformed_one_is_refused(tmp_path):
    plain = tmp_path / 'plain.yaml'
    plain.write_text('motor: x\n')
    assert Calibrated(plain).envelope is None
    bad = tmp_path / 'bad.yaml'
    bad.write_text('coverage:\n  envelope:\n    positive: {dp_mpa: [5, 1], speed_rpm: [0, 1]}\n')
    with pytest.raises(DataError, match=r'coverage\.envelope\.positive\.dp_mpa'):
        Calibrated(bad).envelope


def test_the_samples_left_out_of_every_row_are_counted_by_reason():
    table = generate_transient(Plan(liquid='oil'), Injection(), REALISTIC_DYNAMICS, seed=3,
                               duration_s=20.0)
    flow = table.flow.copy()
    flow[100:107] = np.nan
    samples = transient_samples(MotorModel.default('oil'), replace(table, flow=flow))
    note = samples.table.notes[-1]
    assert 'left out: 7 without a finite reading' in note
    assert samples.n_samples < len(table) - 6


def _spiked(duration_s, seed=3):
    table = generate_transient(Plan(liquid='oil'), Injection(), REALISTIC_DYNAMICS, seed=seed,
                               duration_s=duration_s)
    return table, len(table) // 2


def test_a_one_sample_spike_of_the_flow_is_left_out_and_a_step_is_not():
    table, at = _spiked(20.0)
    first = np.zeros(len(table), dtype=bool)
    first[0] = True
    spiked = table.flow.copy()
    spiked[at] += 2.0 * LPM
    flagged, departure, _ = spikes(spiked, first)
    assert flagged[at] and flagged.sum() <= 2
    assert departure[at] == pytest.approx(2.0 * LPM, rel=0.1)
    stepped = table.flow.copy()
    stepped[at:] += 2.0 * LPM
    assert not spikes(stepped, first)[0][at - 3:at + 3].any()
    samples = transient_samples(MotorModel.default('oil'), replace(table, flow=spiked))
    assert at in samples.spikes and not samples.usable[at]
    assert 'isolated spikes of the flow reading' in samples.table.notes[-1]


def test_a_spike_is_listed_among_the_outliers_by_its_time():
    table, at = _spiked(30.0, seed=5)
    flow = table.flow.copy()
    flow[at] -= 2.0 * LPM
    cal = calibrate(replace(table, flow=flow), 'oil')
    listed = [o for o in cal.summary()['outliers'] if o.get('sample') == at]
    assert listed and listed[0]['time'] == pytest.approx(table.channels['time'][at])
    assert listed[0]['residual_lpm'] == pytest.approx(-2.0, rel=0.1)


def _glitched(table, at):
    speed, p_in = table.speed.copy(), table.p_in.copy()
    speed[at] = 1.0e5 * RPM  # a speed no motor reaches, a pressure far off its course
    p_in[at + 40] += 0.5 * np.ptp(p_in)
    return replace(table, speed=speed, p_in=p_in)


def test_a_spike_of_the_speed_or_a_pressure_is_named_and_mended_to_the_clean_rows():
    table, at = _spiked(20.0)
    model = MotorModel.default('oil')
    clean, samples = (transient_samples(model, t) for t in (table, _glitched(table, at)))
    assert list(zip(samples.spikes, samples.spike_channel)) == [(at, 'speed'), (at + 40, 'p_in')]
    assert samples.spike_size[0] == pytest.approx(1.0e5 * RPM - table.speed[at], rel=0.01)
    assert samples.spike_size[1] == pytest.approx(0.5 * np.ptp(table.p_in), rel=0.1)
    assert 'mended: isolated spikes of 1 speed, 1 p_in reading(s)' in samples.table.notes[-1]
    # each replaced by its neighbours' fit: the same rows, regressors and revolutions
    assert samples.usable.sum() == clean.usable.sum() and len(samples.parts) == len(clean.parts)
    for name in ('speed', 'flow', 'p_in', 'p_out'):
        assert getattr(samples.table, name) == pytest.approx(
            getattr(clean.table, name), rel=1e-3, abs=1e-3), name
    for name, x in samples.parts.nuisance.items():
        assert np.abs(x - clean.parts.nuisance[name]).max() <= 0.05 * np.abs(x).max(), name
    assert samples.table.channels['revolutions'] == pytest.approx(
        clean.table.channels['revolutions'], rel=1e-3)


def test_a_spiked_speed_and_pressure_give_the_clean_figures_and_are_listed(tmp_path):
    table, at = _spiked(30.0, seed=5)
    clean, cal = (calibrate(t, 'oil').summary() for t in (table, _glitched(table, at)))
    for key in ('error_before', 'error_after'):
        assert cal[key]['rmse_lpm'] == pytest.approx(clean[key]['rmse_lpm'], rel=0.02)
    listed = [(o['sample'], o['reading']) for o in cal['outliers'] if 'sample' in o]
    assert listed == [(at, 'speed'), (at + 40, 'p_in')]
    # the summary line counts samples: a mended speed or pressure spike leaves none out
    assert cal['error_over'] == {'what': 'samples', 'n': cal['n_samples'],
                                 'n_with_outliers': cal['n_samples']}
    assert f'over {cal["n_samples"]} samples (' in _errors(cal, True)
    assert 'isolated outlier' not in _errors(cal, True)


@pytest.mark.parametrize('name', MBARI)
def test_the_real_logs_fast_transients_are_not_spikes(name):
    table = read_log(data_path('real', 'mbari_pto', name), load_mapping('mbari_pto'))
    first, _ = segments(table.channels['time'], 3.0)
    assert spikes(table.flow, first)[0].sum() <= 2  # of some 20 000 samples
    # the pressures' ringing and the speed's jitter in the fast moves are not spikes
    found = reading_spikes(table, first)
    assert set(found.channel) <= {'flow'} and found.at.size <= 2


def test_a_wear_over_an_epoch_clock_is_offered_as_over_a_clock_from_zero():
    table = generate_transient(Plan(liquid='oil'), Injection(), REALISTIC_DYNAMICS, seed=3,
                               duration_s=20.0)
    parts, _ = loss_parts(MotorModel.default('oil'), table)
    law = standard_law(MotorModel.default('oil').liquid, 'oil')
    time = np.linspace(0.0, 20.0, len(parts))
    offered = {}
    for start in (0.0, 1.6e9):  # a time column read as seconds since 1970
        candidates, skipped = build_library(parts, {'time': time + start}, law)
        assert not [s for s in skipped if 'wear(time)' in s], skipped
        offered[start] = [c for c in candidates if c.regressor == 'time']
    assert [c.effect for c in offered[1.6e9]] == [c.effect for c in offered[0.0]] != []

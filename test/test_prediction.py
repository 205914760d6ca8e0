# SPDX-License-Identifier: Apache-2.0
"""The combination rule and the prediction, shared by the node and replay (no ROS)."""

import dataclasses
import math

from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from satmotor_ros.model import CoefficientSet, MotorModel, PointStatus
from satmotor_ros.model.effects import effect_from_mapping
from satmotor_ros.model.units import ATMOSPHERE, LPM, MPA
from satmotor_ros.prediction import (combine_batch, Combiner, driving_times, input_state,
                                     INPUTS, InputState, Level, predict, Progress, Rule)

OIL = MotorModel.default('oil')
RULE = Rule(timeout=0.5)
MS = 1_000_000  # one millisecond [ns]


def _combiner(**inputs):
    """Return a Combiner holding `inputs` (name -> (value, t_ns))."""
    combiner = Combiner(RULE)
    for name, (value, t_ns) in inputs.items():
        combiner.update(name, value, t_ns)
    return combiner


def _good(**overrides):
    inputs = {'p_in': (20 * MPA, 0), 'p_out': (0.2 * MPA, 0), 'flow': (20 * LPM, 10 * MS)}
    inputs.update(overrides)
    return _combiner(**inputs)


def test_prediction_equals_the_library_for_the_same_inputs():
    pred = predict(OIL, _good().snapshot(10 * MS), RULE.timeout)
    op = OIL.speed(20 * LPM, 19.8 * MPA)
    assert pred.level == Level.OK and pred.message == 'OK' and pred.valid
    assert pred.output('speed') == pytest.approx(float(op.speed), rel=1e-14)
    assert pred.output('dp') == 19.8 * MPA
    for name, value in op.losses.as_dict().items():
        assert pred.output(name) == pytest.approx(float(value), rel=1e-14, abs=0.0)
    assert math.isnan(pred.output('residual'))
    assert pred.stamp_ns == 10 * MS


@pytest.mark.parametrize(('name', 'value', 'text'), [
    ('p_in', math.nan, 'inlet_pressure.fluid_pressure = nan Pa: not finite'),
    ('flow', math.inf, 'flow_command.data = inf m^3/s: not finite'),
    ('p_out', -3.0, 'outlet_pressure.fluid_pressure = -3.0 Pa: negative'),
    ('p_in', -1e-4, 'inlet_pressure.fluid_pressure = -0.0001 Pa: negative'),
    ('p_case', math.nan, 'case_pressure.fluid_pressure = nan Pa: not finite'),
])
def test_bad_input_gives_no_prediction_and_names_field_and_value(name, value, text):
    pred = predict(OIL, _good(**{name: (value, 5 * MS)}).snapshot(10 * MS), RULE.timeout)
    assert pred.level == Level.ERROR and not pred.valid
    assert text in pred.message
    assert all(math.isnan(v) for v in pred.outputs)


def test_missing_and_stale_inputs_give_no_prediction():
    combiner = _combiner(flow=(20 * LPM, 0), p_in=(20 * MPA, 0))
    pred = predict(OIL, combiner.snapshot(0), RULE.timeout)
    assert pred.level == Level.ERROR and 'outlet_pressure: no message received' in pred.message
    combiner.update('p_out', 1 * MPA, 0)
    combiner.update('flow', 20 * LPM, 600 * MS)
    pred = predict(OIL, combiner.snapshot(600 * MS), RULE.timeout)
    assert pred.level == Level.ERROR
    assert pred.message == ('inlet_pressure: last message 0.6 s old (input_timeout 0.5 s); '
                            'outlet_pressure: last message 0.6 s old (input_timeout 0.5 s)')
    combiner.update('p_in', 20 * MPA, 601 * MS)
    combiner.update('p_out', 1 * MPA, 601 * MS)
    assert predict(OIL, combiner.snapshot(601 * MS), RULE.timeout).level == Level.OK


def test_input_exactly_at_the_timeout_is_still_used():
    pred = predict(OIL, _good(flow=(20 * LPM, 500 * MS)).snapshot(500 * MS), RULE.timeout)
    assert pred.level == Level.OK  # the pressures are exactly 0.5 s old
    pred = predict(OIL, _good(flow=(20 * LPM, 500 * MS)).snapshot(500 * MS + 1),
                   RULE.timeout)
    assert pred.level == Level.ERROR and 'inlet_pressure: last message' in pred.message


def test_zero_flow_is_a_stalled_motor_published_with_a_warning():
    pred = predict(OIL, _good(flow=(0.0, 10 * MS)).snapshot(10 * MS), RULE.timeout)
    assert pred.level == Level.WARN and pred.valid
    assert pred.output('speed') == 0.0 and pred.status & PointStatus.STALLED
    assert 'STALLED' in pred.message and 'flow_command 0.0000 l/min' in pred.message


def test_pressure_beyond_the_model_limit_is_an_error_with_the_model_status():
    pred = predict(OIL, _good(p_in=(60 * MPA, 0)).snapshot(10 * MS), RULE.timeout)
    assert pred.level == Level.ERROR and pred.status & PointStatus.BEYOND_LIMIT
    assert 'BEYOND_LIMIT' in pred.message and 'dp 59.8000 MPa' in pred.message
    assert math.isnan(pred.output('speed'))


def test_extrapolated_point_is_published_with_a_warning():
    pred = predict(OIL, _good(p_in=(40 * MPA, 0)).snapshot(10 * MS), RULE.timeout)
    assert pred.level == Level.WARN and pred.status & PointStatus.EXTRAPOLATED
    assert pred.output('speed') > 0.0


def test_case_pressure_drives_external_leakage_and_blocks_when_stale():
    spec_set = OIL.coefficient_set
    leaky = MotorModel(OIL.geometry, CoefficientSet(
        spec_set.name, spec_set.liquid,
        dataclasses.replace(spec_set.coefficients, external_leakage=1e-12)), OIL.valid_range)
    case = 0.5 * MPA + ATMOSPHERE  # FluidPressure is absolute; eq. (24) takes gauge
    pred = predict(leaky, _good(p_case=(case, 5 * MS)).snapshot(10 * MS),
                   RULE.timeout)
    assert pred.output('p_ex') == 0.5 * MPA
    assert pred.output('external') == pytest.approx(1e-12 * 0.5 * MPA, rel=1e-12)
    ref = leaky.speed(20 * LPM, 19.8 * MPA, p_ex=0.5 * MPA)
    assert pred.output('speed') == pytest.approx(float(ref.speed), rel=1e-14)
    without = predict(leaky, _good().snapshot(10 * MS), RULE.timeout)
    assert without.output('p_ex') == 0.0 and without.output('speed') > pred.output('speed')
    stale = predict(leaky, _good(p_case=(case, 0)).snapshot(900 * MS),
                    RULE.timeout)
    assert stale.level == Level.ERROR and 'case_pressure: last message' in stale.message


def test_measured_speed_gives_the_residual_and_its_absence_only_a_warning():
    pred = predict(OIL, _good(measured_speed=(50.0, 8 * MS)).snapshot(10 * MS),
                   RULE.timeout)
    assert pred.output('residual') == 50.0 - pred.output('speed')
    stale = predict(OIL, _good(measured_speed=(50.0, 0), flow=(20 * LPM, 700 * MS),
                               p_in=(20 * MPA, 700 * MS), p_out=(0.2 * MPA, 700 * MS))
                    .snapshot(700 * MS), RULE.timeout)
    assert stale.level == Level.WARN and stale.valid and math.isnan(stale.output('residual'))
    assert 'joint_states: last message 0.7 s old' in stale.message
    odd_temp = predict(OIL, _good(temperature=(math.nan, 1)).snapshot(10 * MS),
                       RULE.timeout)
    assert odd_temp.level == Level.WARN and 'fluid_temperature.temperature = nan' \
        in odd_temp.message


@pytest.mark.parametrize(('kwargs', 'text'), [
    ({'timeout': 0.0}, 'timeout = 0.0 s'), ({'timeout': math.nan}, 'timeout = nan'),
    ({'mode': 'sometimes'}, "mode = 'sometimes'"), ({'rate': -1.0}, 'rate = -1.0 Hz'),
])
def test_rule_rejects_bad_settings_naming_them(kwargs, text):
    with pytest.raises(ValueError, match=text):
        Rule(**kwargs)


def test_driving_times_follow_the_mode():
    flow_t = np.array([5, 17, 30], dtype=np.int64)
    on_flow = driving_times(Rule(), flow_t, 0, 40)
    assert on_flow.tolist() == [5, 17, 30] and on_flow is not flow_t
    ticks = driving_times(Rule(mode='rate', rate=100.0), flow_t, 0, 40 * MS)
    assert ticks.tolist() == [0, 10 * MS, 20 * MS, 30 * MS, 40 * MS]


@settings(max_examples=300, deadline=None)
@given(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from(INPUTS),
       st.sampled_from([math.nan, 0.0, 5e8, 5e8 + 1.0]))
def test_input_state_is_the_same_on_a_float_and_on_an_array(value, name, age_ns):
    one = input_state(name, value, age_ns, RULE.timeout_ns)
    many = input_state(name, np.array([value, value]), np.array([age_ns, age_ns]),
                       RULE.timeout_ns)
    assert many.tolist() == [one, one]


def _random_events(rng, n):
    """
    Return time-ordered (name, value, t_ns) events with bad values, gaps and repeats.

    Times strictly increase: the order of messages logged in the same nanosecond is the
    rule's one documented ambiguity (replay counts them as before the driving message).
    """
    names = ['flow', 'p_in', 'p_out', 'p_case', 'temperature', 'measured_speed']
    weights = np.array([4, 3, 3, 1, 1, 2], dtype=float)
    t, events = 0, []
    for _ in range(n):
        t += int(rng.choice([1000, 1 * MS, 20 * MS, 300 * MS, 800 * MS], p=[.1, .5, .3, .07, .03]))
        name = names[rng.choice(len(names), p=weights / weights.sum())]
        scale = {'flow': 40 * LPM, 'p_in': 30 * MPA, 'p_out': 3 * MPA, 'p_case': 1 * MPA,
                 'temperature': 60.0, 'measured_speed': 150.0}[name]
        value = float(rng.choice([rng.uniform(0, 1), 0.0, -0.1, math.nan, math.inf, 2.0],
                                 p=[.8, .04, .04, .04, .04, .04])) * scale
        events.append((name, value, t))
    return events


def _calibrated():
    """Return the oil model with effects on case pressure, temperature, time and fitted forms."""
    k_ex = 1e-12
    effects = (
        effect_from_mapping('external_leakage', {'regressor': 'p_case', 'coefficient': k_ex}, 'e'),
        effect_from_mapping('viscosity_temperature', {
            'coefficient': 3.7, 'law': 'walther', 'reference_temperature': 40.0,
            'reference_viscosity': 4e-5}, 'e'),
        effect_from_mapping('clearance_wear', {'regressor': 'time', 'coefficient': 1e-8,
                                               'reference': 0.0}, 'e'),
        effect_from_mapping('channel:revolutions', {'coefficient': 1e-9, 'reference': 0.0},
                            'e'),
        effect_from_mapping('term:dp^0.76', {'coefficient': 3e-11}, 'e'),
        effect_from_mapping('threshold:dp', {'coefficient': 1e-13, 'reference': 15e6,
                                             'exponent': 1.2}, 'e'))
    coef = dataclasses.replace(OIL.coef, external_leakage=k_ex)
    fitted = dataclasses.replace(OIL.coefficient_set, coefficients=coef, effects=effects,
                                 viscosity_range=(1e-6, 1e-3))
    return MotorModel(OIL.geometry, fitted, OIL.valid_range)


CALIBRATED = _calibrated()


def test_effects_read_their_channels_and_block_without_them():
    assert CALIBRATED.channels == ('p_case', 'revolutions', 'temperature', 'time')
    case = 0.5 * MPA + ATMOSPHERE
    snap = _good(p_case=(case, 5 * MS), temperature=(55.0, 5 * MS)).snapshot(10 * MS)
    pred = predict(CALIBRATED, snap, RULE.timeout, (0.01, 0.0))
    ref = CALIBRATED.speed_point(20 * LPM, 19.8 * MPA,
                                 channels={'p_case': 0.5 * MPA, 'temperature': 55.0,
                                           'time': 0.01, 'revolutions': 0.0})
    assert pred.level < Level.ERROR and pred.output('speed') == ref.speed
    assert pred.output('external') == pytest.approx(1e-12 * 0.5 * MPA, rel=1e-12)
    later = predict(CALIBRATED, snap, RULE.timeout, (100.0, 0.0))  # worn: less speed
    assert later.output('speed') < pred.output('speed')
    missing = predict(CALIBRATED, _good(p_case=(case, 5 * MS)).snapshot(10 * MS),
                      RULE.timeout)
    assert missing.level == Level.ERROR and not missing.valid
    assert 'needs fluid_temperature.temperature: missing' in missing.message


def test_speed_sensor_gain_corrects_the_measured_speed_in_the_residual():
    effects = (effect_from_mapping('speed_sensor_gain', {'coefficient': 0.1}, 'e'),)
    model = MotorModel(OIL.geometry, dataclasses.replace(OIL.coefficient_set, effects=effects),
                       OIL.valid_range)
    snap = _good(measured_speed=(55.0, 8 * MS)).snapshot(10 * MS)
    pred = predict(model, snap, RULE.timeout)
    assert pred.output('residual') == pytest.approx(55.0 / 1.1 - pred.output('speed'))


@pytest.mark.parametrize('model', [OIL, CALIBRATED], ids=['packaged', 'calibrated'])
@pytest.mark.parametrize('seed', range(6))
def test_live_rule_and_batch_rule_give_identical_predictions(seed, model):
    """The node's per-message path and replay's array path agree (model paths to 1e-12)."""
    rng = np.random.default_rng(seed)
    events = _random_events(rng, 400)
    combiner, live, snaps, progress = Combiner(RULE), [], [], Progress()
    for name, value, t in events:
        combiner.update(name, value, t)
        if name == 'flow':
            snaps.append(combiner.snapshot(t))
            live.append(predict(model, snaps[-1], RULE.timeout,
                                progress.advance(snaps[-1])))
    series = {}
    for name in INPUTS:
        mine = [(t, v) for n, v, t in events if n == name]
        series[name] = (np.array([t for t, _ in mine], dtype=np.int64),
                        np.array([v for _, v in mine]))
    stamps = driving_times(RULE, series['flow'][0], events[0][2], events[-1][2])
    recorded = combine_batch(RULE, stamps, series)
    batch = predict(model, recorded, RULE.timeout, Progress().advance(recorded))
    assert len(batch) == len(live) > 50
    assert {p.level for p in live} == {0, 1, 2}
    for i, pred in enumerate(live):
        assert batch.snapshot(i).states == snaps[i].states
        np.testing.assert_array_equal(batch.snapshot(i).ages, snaps[i].ages)
        assert int(batch.level[i]) == pred.level, (i, pred.message, batch.message(i))
        assert int(batch.status[i]) == pred.status
        assert batch.message(i) == pred.message
        np.testing.assert_allclose(batch.outputs[:, i], np.array(pred.outputs), rtol=1e-12,
                                   atol=1e-300)
        np.testing.assert_array_equal(batch.snapshots.values[:, i], np.array(pred.inputs))


def test_progress_counts_time_and_measured_revolutions_from_the_first_prediction():
    progress = Progress()
    assert progress.peek(5 * MS) == (0.0, 0.0)
    first = _good(measured_speed=(2 * math.pi, 1 * MS)).snapshot(10 * MS)
    assert progress.advance(first) == (0.0, 0.0)
    second = _good(measured_speed=(2 * math.pi, 1010 * MS)).snapshot(1010 * MS)
    time, turns = progress.advance(second)
    assert time == pytest.approx(1.0) and turns == pytest.approx(1.0)  # 1 rev/s for 1 s
    stale = _good().snapshot(3010 * MS)  # no measured speed: no revolutions counted
    assert progress.advance(stale) == (pytest.approx(3.0), pytest.approx(1.0))
    assert progress.peek(4010 * MS) == (pytest.approx(4.0), pytest.approx(1.0))


def test_p_ex_output_is_the_pressure_the_leakage_effect_read():
    effects = (effect_from_mapping('external_leakage', {'regressor': 'p_out',
                                                        'coefficient': 1e-12}, 'e'),)
    coef = dataclasses.replace(OIL.coef, external_leakage=1e-12)
    model = MotorModel(OIL.geometry, dataclasses.replace(
        OIL.coefficient_set, coefficients=coef, effects=effects), OIL.valid_range)
    snap = _good(p_case=(0.5 * MPA + ATMOSPHERE, 5 * MS)).snapshot(10 * MS)
    pred = predict(model, snap, RULE.timeout)
    assert pred.output('p_ex') == 0.2 * MPA - ATMOSPHERE  # gauge p_out, not p_case
    assert pred.output('external') == pytest.approx(1e-12 * (0.2 * MPA - ATMOSPHERE))
    t = np.array([5 * MS, 10 * MS], dtype=np.int64)
    series = {'flow': (t[1:], np.array([20 * LPM])), 'p_in': (t[:1], np.array([20 * MPA])),
              'p_out': (t[:1], np.array([0.2 * MPA])),
              'p_case': (t[:1], np.array([0.5 * MPA + ATMOSPHERE]))}
    batch = predict(model, combine_batch(RULE, t[1:], series), RULE.timeout)
    assert batch.output('p_ex')[0] == pred.output('p_ex')


@pytest.mark.parametrize('name', INPUTS)
def test_input_state_follows_the_rule_priority_on_floats_and_arrays(name):
    """Missing before stale before not finite before negative (absolute pressures only)."""
    non_negative = name in ('p_in', 'p_out', 'p_case')
    values = [0.0, 1.0, -1.0, math.nan, math.inf, -math.inf]
    ages = [math.nan, 0.0, float(RULE.timeout_ns), RULE.timeout_ns + 1.0]
    for value in values:
        for age in ages:
            expected = (InputState.MISSING if math.isnan(age) else
                        InputState.STALE if age > RULE.timeout_ns else
                        InputState.NOT_FINITE if not math.isfinite(value) else
                        InputState.NEGATIVE if value < 0.0 and non_negative else
                        InputState.FRESH)
            one = input_state(name, value, age, RULE.timeout_ns)
            many = input_state(name, np.array([value]), np.array([age]), RULE.timeout_ns)
            assert one == expected == many[0], (value, age)


def test_the_model_note_shows_hydraulic_units_and_no_negative_zero():
    from satmotor_ros.prediction.predict import _model_note
    assert _model_note(4, -1e-12, -1e-3) == ('model status EXTRAPOLATED at flow_command 0.0000 '
                                             'l/min, dp 0.0000 MPa')
    assert _model_note(4, -5 * LPM, 19.5 * MPA).endswith('-5.0000 l/min, dp 19.5000 MPa')

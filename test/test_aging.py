# SPDX-License-Identifier: Apache-2.0
"""The virtual motor and the synthetic recordings age: wear over hours, a step fault at a time."""

import dataclasses
import math

import numpy as np
import pytest

from satmotor_ros.identify.synthetic import (aging, generate, generate_series, Injection, Plan,
                                             wear_kind)
from satmotor_ros.model.effects import Effect
from satmotor_ros.model.units import LPM, MPA
from satmotor_ros.options import MotorOptions
from satmotor_ros.plant import ConstantLoad, Plant, PlantError, PlantParams, SensorParams, \
    SensorSet
from satmotor_ros.plant.config import flat_from_params, params_from_flat
from satmotor_ros.plant.params import FaultParams

FLOW = 20.0 * LPM
LOAD = 50.0
FAMILIES = ('sliwinski2017', 'balawender', 'paszota')


def _model(family):
    return MotorOptions(family=family).build_model()


def _plant(family='sliwinski2017', seed=0, sensors=None, **flat):
    params = params_from_flat(flat, PlantParams(seed=seed, sensors=sensors or SensorSet()))
    return Plant(_model(family), params, load=ConstantLoad(LOAD))


@pytest.mark.parametrize('family', FAMILIES)
def test_wear_rate_grows_the_family_wear_with_the_plants_running_time(family):
    """effects.<wear>_rate: the clearances (or the leakage) grow by rate * t, not per rev."""
    kind = wear_kind(family)
    rate = 2.0e-8 if kind == 'clearance_wear' else 0.01
    plant = _plant(family, **{f'effects.{kind}_rate': rate})
    assert plant.params.effects == (Effect(kind, rate, 'time'),)
    plant.run(5000, FLOW)
    t = plant.state.time
    base = _model(family)
    if kind == 'clearance_wear':
        h0 = base.geometry.clearance_rotor
        grown = plant.model.geometry.clearance_rotor - h0
        assert grown == pytest.approx(rate * t, abs=0.005 * h0)
        assert grown > 0.5 * rate * t
    else:
        fam = base.family
        expected = fam.scaled(base.coefficient_set.coefficients,
                              dict.fromkeys(fam.leakage, 1.0 + rate * t))
        got = dataclasses.asdict(plant.model.coefficient_set.coefficients)
        new = dataclasses.asdict(base.coefficient_set.coefficients)
        grew = 0
        for name, value in dataclasses.asdict(expected).items():
            if isinstance(value, float) and math.isfinite(value):
                assert got[name] == pytest.approx(value, rel=0.006), name
                grew += abs(got[name]) > abs(new[name]) * 1.01
        assert grew >= 1
    assert plant.rebuilds >= 1


def test_a_wear_grows_with_revolutions_or_with_time_never_both():
    """Both parameters of one wear are refused, naming them; each alone round-trips."""
    with pytest.raises(PlantError, match='clearance_wear_rate'):
        params_from_flat({'effects.clearance_wear': 1e-9, 'effects.clearance_wear_rate': 1e-9})
    for name, regressor in (('leakage_wear', 'revolutions'), ('leakage_wear_rate', 'time')):
        params = params_from_flat({f'effects.{name}': 1e-3})
        assert params.effects == (Effect('leakage_wear', 1e-3, regressor),)
        assert params_from_flat(flat_from_params(params)) == params


@pytest.mark.parametrize('family', FAMILIES)
def test_step_fault_strikes_once_the_plant_clock_reaches_its_time(family):
    """A seal starts passing at t = 2 s: no leakage before, k p_case after; state carried."""
    k = 2.0e-12
    plant = _plant(family, **{'fault.time': 2.0, 'fault.effect': 'external_leakage',
                              'fault.value': k})
    healthy = _plant(family)
    while True:
        plant.step(FLOW)
        healthy.step(FLOW)
        if plant.state.time >= 2.0:
            break
        assert not plant.fault_struck and plant.flows.leakage == 0.0
    assert plant.state == healthy.state  # it strikes at the end of the step reaching 2 s
    assert plant.fault_struck and plant.state.time == pytest.approx(2.0, abs=1e-12)
    plant.run(3000, FLOW)
    gauge = plant.case_pressure() - plant.params.lines.tank_pressure
    assert plant.flows.leakage == pytest.approx(k * gauge, rel=1e-9)
    assert plant.params.effects == ()  # the configured motor is unchanged; the fault is on top
    plant.reset()
    assert not plant.fault_struck
    plant.run(10, FLOW)
    assert plant.flows.leakage == 0.0


def test_sensor_fault_changes_the_reading_from_its_time_and_the_noise_runs_on():
    """A flowmeter gain step: same noise draws as the healthy plant, times 1 + g after t_f."""
    g, noisy = 0.05, SensorSet(flow=SensorParams(noise=0.01 * LPM))
    faulty = _plant(seed=4, sensors=noisy, **{'fault.time': 0.5, 'fault.effect':
                                              'flow_sensor_gain', 'fault.value': g})
    healthy = _plant(seed=4, sensors=noisy)
    for _ in range(1000):
        faulty.step(FLOW)
        healthy.step(FLOW)
        got, ref = faulty.measure().flow, healthy.measure().flow
        truth = healthy.flows.motor
        if faulty.state.time < 0.5 - 1e-9:
            assert got == ref
        else:
            assert got - (1.0 + g) * truth == pytest.approx(ref - truth, abs=1e-15)
    assert faulty.state == healthy.state


def test_reconfigure_after_the_fault_keeps_it_and_can_lift_it():
    """A parameter change after the strike re-applies the fault; removing it heals the plant."""
    plant = _plant(**{'fault.time': 0.1, 'fault.effect': 'external_leakage',
                      'fault.value': 1e-12})
    plant.run(300, FLOW)
    plant.reconfigure(dataclasses.replace(plant.params, pump_lag=0.05))
    plant.run(2, FLOW)
    assert plant.fault_struck and plant.flows.leakage > 0.0
    plant.reconfigure(dataclasses.replace(plant.params, fault=FaultParams()))
    plant.run(2, FLOW)
    assert not plant.fault_struck and plant.flows.leakage == 0.0


@pytest.mark.parametrize(('flat', 'match'), [
    ({'fault.effect': 'seal'}, "FaultParams.effect = 'seal'"),
    ({'fault.effect': 'leakage_driver'}, 'FaultParams.effect'),
    ({'fault.effect': 'external_leakage', 'fault.value': 1.0}, r'outside \[0, 1e-08\]'),
    ({'fault.time': -1.0}, 'FaultParams.time'),
])
def test_bad_faults_are_refused_naming_the_field(flat, match):
    """An unknown effect parameter, a value outside its range, a negative time."""
    with pytest.raises(PlantError, match=match):
        params_from_flat(flat)


def test_a_fault_the_family_cannot_have_fails_at_set_up_not_when_it_strikes():
    """clearance_wear on a paszota motor (it has no clearances) is refused by the plant."""
    with pytest.raises(PlantError, match='clearance_wear'):
        _plant('paszota', **{'fault.time': 1e6, 'fault.effect': 'clearance_wear',
                             'fault.value': 1e-9})


# -- synthetic recordings ----------------------------------------------------------------


def _series(plan, injections, samples=4000, seed=3):
    return generate_series(plan, injections, seed=seed, samples=samples, rate=1.0, hold_s=20.0)


@pytest.mark.parametrize('family', ['', 'balawender', 'paszota'])
def test_synthetic_wear_grows_over_the_recording_in_every_family(family):
    """aging(): the family's wear adds a loss that grows with the hours, 0 at the start."""
    plan = Plan(family=family)
    clean = _series(plan, [Injection()])
    worn = _series(plan, aging(family, wear=1.0))
    extra = (worn.flow - clean.flow) / LPM
    time = worn.channels['time']
    first, last = extra[time < 400.0], extra[time > time[-1] - 400.0]
    assert abs(np.mean(first)) < 0.1 * np.mean(last)
    assert np.mean(last) > 0.05  # l/min: well above the averaged noise
    quarters = [np.mean(q) for q in np.array_split(extra, 4)]
    assert quarters == sorted(quarters)
    assert np.array_equal(worn.speed, clean.speed)


def test_synthetic_step_fault_is_absent_before_its_onset_and_present_after():
    """A leak from t = 2000 s: the rows before are the clean recording's, bit for bit."""
    plan, onset = Plan(), 2000.0
    clean = _series(plan, [Injection()])
    leak = Injection('external_leakage', 0.4 * LPM / MPA, 'p_case', onset=onset)
    faulty = _series(plan, [leak])
    time = clean.channels['time']
    before, after = time < onset, time >= onset
    assert np.array_equal(faulty.flow[before], clean.flow[before])
    extra = (faulty.flow - clean.flow)[after]
    p_case = clean.channels['p_case'][after]
    assert np.allclose(extra, 0.4 * LPM / MPA * np.maximum(p_case, 0.0), rtol=0.02,
                       atol=0.05 * LPM)
    assert np.mean(extra) > 0.05 * LPM


def test_synthetic_sensor_fault_and_wear_onset_act_from_their_time_only():
    """A flowmeter gain step and a wear that starts growing at its onset."""
    plan, onset = Plan(), 1500.0
    clean = _series(plan, [Injection()], samples=3000)
    time = clean.channels['time']
    gain = _series(plan, [Injection('flow_sensor_gain', 0.02, 'flow', onset=onset)],
                   samples=3000)
    before = time < onset
    assert np.array_equal(gain.flow[before], clean.flow[before])
    assert np.allclose(gain.flow[~before], 1.02 * clean.flow[~before], rtol=1e-3,
                       atol=0.2 * LPM)
    worn = _series(plan, [Injection('clearance_wear', 1.5e-6, 'time', onset=onset)],
                   samples=3000)
    assert np.array_equal(worn.flow[before], clean.flow[before])
    extra = worn.flow - clean.flow
    late, early = extra[time > time[-1] - 300.0], extra[(time >= onset) & (time < onset + 100)]
    assert np.mean(late) > 0.05 * LPM
    assert np.mean(early) < 0.2 * np.mean(late)


def test_bench_tables_without_onsets_are_unchanged_and_families_differ():
    """generate() as before for the packaged motor; a family's motor gives other flows."""
    table = generate(Plan(n_points=50), Injection(), seed=1)
    again = generate(Plan(n_points=50, family='sliwinski2017'), Injection(), seed=1)
    assert np.allclose(table.flow, again.flow, rtol=1e-12)
    other = generate(Plan(n_points=50, family='paszota'), Injection(), seed=1)
    assert not np.allclose(table.flow, other.flow, rtol=1e-3)
    assert math.isinf(Injection().onset)


def test_an_ageing_recording_can_have_a_tanks_temperature_that_moves_its_losses():
    """temperature_jitter 0: smooth; temperature_span: the losses follow it (thinner when hot)."""
    plan = Plan(temperature_jitter=0.0)
    cold = _series(plan, aging(wear=0.0), samples=2000)
    warm = _series(plan, aging(wear=0.0, temperature_span=10.0), samples=2000)
    temperature = warm.channels['temperature']
    jittered = _series(Plan(), aging(wear=0.0, temperature_span=10.0),
                       samples=2000).channels['temperature']

    def jumps(t):  # steps beyond 1.5 K: the sensor's noise (0.3 K) all but never makes one
        return np.mean(np.abs(np.diff(t)) > 1.5)
    assert jumps(temperature) < 0.003 < jumps(jittered)
    extra = warm.flow - cold.flow
    hot = temperature > np.median(temperature)
    assert np.mean(extra[hot]) > np.mean(extra[~hot]) + 0.01 * LPM
    assert np.array_equal(_series(Plan(), [Injection()], samples=200).flow,
                          _series(Plan(temperature_jitter=0.3), [Injection()], samples=200).flow)


def test_a_recordings_temperature_moves_only_when_its_losses_follow_it():
    """
    No viscosity_temperature: the oil is held at one temperature (only the sensor's noise).

    That temperature is where the liquid's standard law gives the model's viscosity (43.1 degC
    for the packaged oil, 27.1 degC for water), the one the health baseline refers to.
    """
    for liquid, at in (('oil', 43.11), ('water', 27.09)):
        held = _series(Plan(liquid=liquid), [Injection()], samples=2000).channels['temperature']
        assert np.std(held) < 0.5 and abs(np.mean(held) - at) < 0.05
    swing = _series(Plan(), aging(wear=0.0, temperature_span=10.0),
                    samples=2000).channels['temperature']
    assert np.ptp(swing) > 8.0
    # a bench table's points keep their drawn temperatures (a channel calibration must ignore)
    assert np.ptp(generate(Plan(n_points=50), Injection(), seed=1).channels['temperature']) > 5.0

# SPDX-License-Identifier: Apache-2.0
"""The health estimator: the leakage factor, the change detector, the trend, the state file."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

from health_data import blocks, DISPLACEMENT, recording
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest

from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.health import (Baseline, HealthMonitor, HealthSamples,
                                          HealthSettings)
from satmotor_ros.identify.health.detector import Cusum, siegmund_arl, threshold_for

QUIET = HealthSettings(explain=False)


def _run(samples: HealthSamples, monitor: HealthMonitor, size: int = 4000) -> list:
    alarms = []
    for block in blocks(samples, size):
        alarms += monitor.update(block)
    return alarms


@settings(max_examples=8, deadline=None, derandomize=True)
@given(family=st.sampled_from(['paszota', 'balawender', 'sliwinski2017']),
       displacement=st.floats(5e-7, 2e-5))
def test_leakage_factor_is_one_on_the_baselines_own_noise_free_data(family: str,
                                                                    displacement: float) -> None:
    """Noise-free data from the baseline itself give a factor of 1, and no alarm."""
    baseline = Baseline.for_family(family, displacement)
    samples = recording(0.3, noise_lpm=0.0, baseline=baseline, rate_hz=2.0)
    monitor = HealthMonitor(baseline, dataclasses.replace(QUIET, learn_hours=0.1))
    assert _run(samples, monitor) == []
    snap = monitor.snapshot()
    assert snap.leakage_factor.value == pytest.approx(1.0, abs=1e-6)
    assert not snap.learning


def test_step_of_twenty_percent_is_found_within_minutes_with_its_size() -> None:
    """A +20 % step in the losses raises one change alarm soon, naming the new level."""
    samples = recording(2.0, seed=3, scale=lambda t: np.where(t >= 3600.0, 1.2, 1.0))
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
    alarms = _run(samples, monitor)
    assert [a.kind for a in alarms] == ['change']
    assert 3600.0 <= alarms[0].time_s <= 3600.0 + 300.0
    assert abs(alarms[0].change_s - 3600.0) <= 120.0
    (settled,) = monitor.snapshot().alarms
    assert settled.after / settled.before == pytest.approx(1.2, abs=0.06)
    assert monitor.snapshot().leakage_factor.value == pytest.approx(1.2, abs=0.06)


def test_clean_recording_raises_no_alarm_and_the_interval_covers_one() -> None:
    """Hours of clean, correlated noise: no alarm; the window's interval holds the truth."""
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
    assert _run(recording(6.0, seed=5), monitor) == []
    snap = monitor.snapshot()
    assert snap.leakage_factor.low <= 1.0 <= snap.leakage_factor.high
    assert snap.statistic < 1.0
    assert snap.noise['bin_inflation'] > 1.0  # the correlated noise is seen, not assumed away


def test_threshold_inverts_the_run_length_and_grows_with_the_false_alarm_interval() -> None:
    """The threshold gives back the run length asked for; a longer interval, a higher one."""
    h = threshold_for(1.0e5, 0.7)
    assert siegmund_arl(h, 0.7) == pytest.approx(1.0e5, rel=1e-6)
    assert threshold_for(1.0e6, 0.7) > h


@pytest.mark.parametrize('delta', [0.5, 1.0, 2.0])
def test_the_cusum_on_standard_noise_runs_as_long_as_siegmund_says(delta: float) -> None:
    """In control, the two-sided CUSUM alarms after half Siegmund's one-sided run length."""
    h = threshold_for(400.0, delta)
    rng = np.random.default_rng(7)
    runs = []
    for _ in range(400):
        cusum = Cusum(h)
        n = 0
        while max(cusum.up, cusum.down) < h:
            cusum.step(float(rng.standard_normal()), delta, float(n))
            n += 1
        runs.append(n)
        cusum.reset()
        assert (cusum.up, cusum.down) == (0.0, 0.0)
    # 400 runs of a roughly exponential length: the mean within about 3 standard errors
    assert np.mean(runs) == pytest.approx(200.0, rel=0.15)
    assert siegmund_arl(5.0, 1.0) == pytest.approx(938.0, abs=0.5)  # the docstring's figure


def test_false_alarm_hours_sets_the_threshold() -> None:
    """The threshold comes from false_alarm_hours: ten times the interval, a higher h."""
    samples = recording(0.5, seed=2)
    low, high = (HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT),
                               dataclasses.replace(QUIET, false_alarm_hours=hours))
                 for hours in (100.0, 10000.0))
    _run(samples, low)
    _run(samples, high)
    assert high.snapshot().threshold > low.snapshot().threshold + 1.0


def test_linear_wear_gives_hours_to_limit_within_thirty_percent_from_halfway() -> None:
    """Losses growing linearly to the limit (2x) at 20 h: at 10 h, about 10 h to go."""
    samples = recording(10.0, seed=7, rate_hz=1.0,
                        scale=lambda t: 1.0 + t / (20.0 * 3600.0))
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
    _run(samples, monitor, 20000)
    snap = monitor.snapshot()
    assert snap.hours_to_limit.value == pytest.approx(10.0, rel=0.3)
    assert snap.hours_to_limit.low <= 10.0 <= snap.hours_to_limit.high
    assert snap.trend_per_hour.value == pytest.approx(0.05, rel=0.3)


def _as_defined(clean: HealthSamples, baseline: Baseline, scale: np.ndarray | float,
                noisy: HealthSamples | None = None) -> HealthSamples:
    """
    Return `clean` with its flow's Q_vl `scale` times the baseline's at that flow.

    The monitor's definition of the factor: the flow solves Q = q_t n + scale Q_vl(Q), the
    chamber drop taken at Q itself (fixed-point steps); `noisy`'s noise is then added.
    """
    flow = clean.flow
    forward = np.where(clean.p_in - clean.p_out < 0.0, -1.0, 1.0)
    for _ in range(5):
        losses = baseline.losses(dataclasses.replace(clean, flow=flow), QUIET.min_speed)
        flow = flow + np.where(losses.reason == 0,
                               forward * (scale * losses.baseline - losses.measured), 0.0)
    if noisy is not None:
        flow = flow + noisy.flow - clean.flow
    return dataclasses.replace(clean, flow=flow)


@pytest.mark.parametrize('family', ['paszota', 'balawender'])
def test_a_large_factor_made_as_defined_is_read_without_bias(family: str) -> None:
    """
    Q_vl 1.75x the baseline's at the measured point: the factor reads 1.75, not ~1 % more.

    Scaling the healthy flow's loss instead (the channel drop left at the healthy flow) reads
    1.752-1.754 here and 1.76 on the MBARI trajectories: a monitor that moved its baseline off
    the measured point, or a weighting that leans on the large factors, fails this.
    """
    baseline = Baseline.for_family(family, DISPLACEMENT)
    clean = recording(0.5, noise_lpm=0.0, baseline=baseline, rate_hz=2.0)
    monitor = HealthMonitor(baseline, dataclasses.replace(QUIET, learn_hours=0.1))
    assert _run(_as_defined(clean, baseline, 1.75), monitor) == []
    assert monitor.snapshot().leakage_factor.value == pytest.approx(1.75, abs=1e-4)


def test_late_in_a_linear_wear_the_interval_still_holds_the_hours_to_limit() -> None:
    """
    At 75 % of the way to the limit (2x at 20 h, Q_vl as defined): 5 h to go, inside the CI.

    The bench's 20 runs on the MBARI trajectories held the truth in 10 of 20 at 75 % while
    their truth was off the factor's definition (bench/bench_health.py); this guards the
    late interval and its bias on the tests' own generator (seeded).
    """
    baseline = Baseline.for_family('paszota', DISPLACEMENT)
    clean = recording(15.0, seed=3, rate_hz=1.0, noise_lpm=0.0)
    samples = _as_defined(clean, baseline, 1.0 + clean.time / (20.0 * 3600.0),
                          recording(15.0, seed=3, rate_hz=1.0))
    monitor = HealthMonitor(baseline, QUIET)
    assert _run(samples, monitor, 20000) == []
    snap = monitor.snapshot()
    assert snap.hours_to_limit.low <= 5.0 <= snap.hours_to_limit.high
    assert snap.hours_to_limit.value == pytest.approx(5.0, rel=0.1)
    assert snap.trend.value == pytest.approx(1.75, abs=0.02)


def test_unusable_samples_are_counted_and_skipped() -> None:
    """Non-finite, gross, stalled and repeated samples are counted by reason, not folded in."""
    samples = recording(0.2, seed=1, noise_lpm=0.0)
    flow, speed, time = samples.flow.copy(), samples.speed.copy(), samples.time.copy()
    flow[10:20] = np.nan
    flow[30:40] = 1.0  # absurd but finite: would move the factor if it were used
    speed[30:40] = 0.0  # a gross reading is implausible, stopped or not
    speed[60:70] = 0.0
    time[50] = time[49]
    bad = dataclasses.replace(samples, flow=flow, speed=speed, time=time)
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT),
                            dataclasses.replace(QUIET, learn_hours=0.05))
    _run(bad, monitor)
    snap = monitor.snapshot()
    assert snap.skipped['non_finite'] == 10
    assert snap.skipped['stalled'] == 10 and snap.skipped['implausible'] == 10
    assert snap.skipped['stale'] == 1
    assert snap.n_skipped == 31 and snap.n_samples == len(samples)
    assert snap.leakage_factor.value == pytest.approx(1.0, abs=1e-6)


def test_state_file_resumes_exactly(tmp_path: Path) -> None:
    """Saved halfway and resumed, the monitor ends where an uninterrupted one does."""
    samples = recording(1.5, seed=4, scale=lambda t: np.where(t >= 3000.0, 1.25, 1.0))
    baseline = Baseline.for_family('paszota', DISPLACEMENT)
    whole = HealthMonitor(baseline, QUIET)
    _run(samples, whole, 3000)
    half = HealthMonitor(baseline, QUIET)
    parts = blocks(samples, 3000)
    for block in parts[:7]:
        half.update(block)
    half.save(tmp_path / 'state.json')
    resumed = HealthMonitor.resume(tmp_path / 'state.json', baseline)
    for block in parts[7:]:
        resumed.update(block)
    a, b = whole.snapshot(), resumed.snapshot()
    assert a.alarms == b.alarms and len(a.alarms) == 1
    assert a.leakage_factor == b.leakage_factor
    assert a.n_samples == b.n_samples


def test_resume_refuses_a_file_that_is_no_state(tmp_path: Path) -> None:
    """A file of another kind is refused with one line naming it."""
    path = tmp_path / 'state.json'
    path.write_text('{"version": 99}')
    with pytest.raises(DataError, match='version'):
        HealthMonitor.resume(path, Baseline.for_family('paszota', DISPLACEMENT))


def test_settings_refuse_meaningless_values() -> None:
    """A non-positive interval or an efficiency limit outside (0, 1) names the field."""
    with pytest.raises(DataError, match='false_alarm_hours'):
        HealthSettings(false_alarm_hours=0.0)
    with pytest.raises(DataError, match='limit_volumetric_efficiency'):
        HealthSettings(limit_volumetric_efficiency=1.5)


def test_efficiency_limit_becomes_a_leakage_factor_at_the_reference_point() -> None:
    """limit_volumetric_efficiency is turned into the factor that gives it at the reference."""
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT),
                            dataclasses.replace(QUIET, limit_volumetric_efficiency=0.9,
                                                learn_hours=0.1))
    _run(recording(0.3, seed=1), monitor)
    snap = monitor.snapshot()
    qn = DISPLACEMENT * snap.reference_speed
    eta_at_limit = qn / (qn + snap.limit_leakage_factor * monitor.reference_loss)
    assert eta_at_limit == pytest.approx(0.9)
    assert math.isfinite(snap.volumetric_efficiency_reference.value)


def test_a_change_is_named_by_the_calibration_candidates_after_relearning() -> None:
    """A +30 % step: 'pending' when raised, then a wear of the losses once learned."""
    samples = recording(2.0, seed=6, rate_hz=2.0,
                        scale=lambda t: np.where(t >= 3600.0, 1.3, 1.0))
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT),
                            dataclasses.replace(QUIET, explain=True))
    alarms = _run(samples, monitor)
    assert [a.what for a in alarms] == ['pending']
    (named,) = monitor.snapshot().alarms
    assert named.what.startswith('wear') and 'x1.' in named.what
    assert monitor.snapshot().what_changed == named.what


def test_a_change_without_explanation_says_unexplained_at_once() -> None:
    """With explain off the alarm is final when raised."""
    samples = recording(1.5, seed=6, scale=lambda t: np.where(t >= 3600.0, 1.3, 1.0))
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
    assert [a.what for a in _run(samples, monitor)] == ['unexplained']


def test_figures_do_not_depend_on_how_the_samples_are_cut_into_blocks() -> None:
    """One block or blocks of 7 samples (a node's 1 s updates): the same alarms and figures."""
    samples = recording(1.6, seed=8, rate_hz=2.0,
                        scale=lambda t: np.where(t >= 3000.0, 1.3, 1.0))
    baseline = Baseline.for_family('paszota', DISPLACEMENT)
    whole = HealthMonitor(baseline, dataclasses.replace(QUIET, explain=True))
    whole.update(samples)
    pieces = HealthMonitor(baseline, dataclasses.replace(QUIET, explain=True))
    _run(samples, pieces, 7)
    a, b = whole.snapshot(), pieces.snapshot()
    assert [(x.kind, x.what, x.time_s) for x in a.alarms] == [
        (x.kind, x.what, x.time_s) for x in b.alarms]
    assert len(a.alarms) == 1 and a.alarms[0].what != 'pending'
    assert a.leakage_factor.value == pytest.approx(b.leakage_factor.value, rel=1e-9)
    assert a.trend_per_hour.value == pytest.approx(b.trend_per_hour.value, rel=1e-9)
    assert (a.n_samples, a.skipped) == (b.n_samples, b.skipped)


@pytest.mark.slow
def test_the_oils_temperature_is_used_so_a_warm_afternoon_is_no_change() -> None:
    """Oil warming and cooling over 30 K: no alarm with temperature, alarms without."""
    from satmotor_ros.identify.synthetic import generate_series, Injection, Plan
    table = generate_series(Plan(family='paszota', displacement=DISPLACEMENT),
                            Injection.realistic('viscosity_temperature'), seed=3,
                            samples=30000, rate=5.0, hold_s=20.0)
    samples = HealthSamples.from_table(table)
    spread, alarms = [], []
    for data in (samples, dataclasses.replace(samples, temperature=None)):
        monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
        alarms.append(_run(data, monitor, 997))
        spread.append(np.std([p.bin_factor for p in monitor.pop_points()]))
    assert alarms[0] == [] and len(alarms[1]) >= 2
    assert spread[0] < 0.5 * spread[1]


@pytest.mark.parametrize('noise_lpm', [0.003, 0.0005])
def test_a_step_is_found_however_quiet_the_flowmeter(noise_lpm: float) -> None:
    """A quiet flowmeter makes a +20 % step many sigma per bin: found all the same, soon."""
    samples = recording(1.0, seed=4, rate_hz=2.0, noise_lpm=noise_lpm,
                        scale=lambda t: np.where(t >= 2400.0, 1.2, 1.0))
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
    alarms = _run(samples, monitor)
    assert [a.kind for a in alarms] == ['change']
    assert 2400.0 <= alarms[0].time_s <= 2400.0 + 300.0


def test_a_long_gap_in_time_costs_no_memory() -> None:
    """A recording 230 days after the last (a bench CSV from 0 s, then an epoch log)."""
    import tracemalloc
    baseline = Baseline.for_family('paszota', DISPLACEMENT)
    monitor = HealthMonitor(baseline, dataclasses.replace(QUIET, learn_hours=0.1))
    monitor.update(recording(0.3, seed=1, rate_hz=2.0))
    later = recording(0.1, seed=2, rate_hz=2.0, t0=2.0e7)  # 230 days on: 2e6 bins
    tracemalloc.start()
    monitor.update(later)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert peak < 20e6
    assert monitor.snapshot().n_samples == 2160 + 720
    assert monitor.snapshot().leakage_factor.value == pytest.approx(1.0, abs=0.1)


def test_a_trend_whose_interval_holds_no_rise_gives_no_hours_to_limit() -> None:
    """A healthy motor: the slope's sign is noise, so no date is given (infinite)."""
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
    _run(recording(3.0, seed=0, rate_hz=1.0), monitor, 20000)
    snap = monitor.snapshot()
    assert snap.trend_per_hour.low <= 0.0
    assert math.isinf(snap.hours_to_limit.value)


def test_resume_refuses_a_state_made_against_another_model(tmp_path: Path) -> None:
    """A state learned on one motor does not judge another: one line names the baseline."""
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
    _run(recording(0.2, seed=1), monitor)
    monitor.save(tmp_path / 'state.json')
    with pytest.raises(DataError, match='baseline'):
        HealthMonitor.resume(tmp_path / 'state.json',
                             Baseline.for_family('balawender', DISPLACEMENT))


def test_first_learning_points_are_flagged_and_carry_no_interval() -> None:
    """Before c^2 and phi are learned a point says learning and gives no interval."""
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
    _run(recording(1.2, seed=20, rate_hz=1.0), monitor)
    points = monitor.pop_points()
    learning = [p for p in points if p.learning]
    learned = [p for p in points if not p.learning]
    assert learning and learned and points[:len(learning)] == learning
    assert all(math.isfinite(p.leakage_factor.value) for p in learning)
    assert all(math.isnan(p.leakage_factor.low) and math.isnan(p.leakage_factor.high)
               for p in learning)
    assert all(p.leakage_factor.low <= p.leakage_factor.value <= p.leakage_factor.high
               for p in learned)


def test_relearning_after_a_change_keeps_the_learned_noise_so_intervals_cover() -> None:
    """After a +30 % step the re-learning windows' intervals hold 1.3 (learned c^2, phi)."""
    baseline = Baseline.for_family('paszota', DISPLACEMENT)
    hits = []
    for seed in range(1, 11):
        samples = recording(2.5, seed=seed, rate_hz=2.0,
                            scale=lambda t: np.where(t >= 3600.0, 1.3, 1.0))
        monitor = HealthMonitor(baseline, QUIET)
        (alarm,) = [a for a in _run(samples, monitor) if a.kind == 'change']
        points = [p for p in monitor.pop_points()
                  if alarm.time_s < p.time_s < alarm.time_s + 2400.0][::30]  # disjoint windows
        assert all(p.learning for p in points[:2])
        hits += [p.leakage_factor.low <= 1.3 <= p.leakage_factor.high for p in points]
    assert len(hits) >= 60
    assert np.mean(hits) >= 0.92


def test_the_default_synthetic_recording_writes_no_temperature_its_losses_ignore() -> None:
    """
    ``satmotor synthetic``'s recording with no effect, read with its temperature: no alarm.

    Its losses do not follow a temperature, so it must not write one that moves: a swing of
    10 K the losses ignored moved this baseline by +-10 % and raised change alarms every hour
    or two; the monitor with and without the temperature column must agree.
    """
    from satmotor_ros.identify.synthetic import generate_series, Injection, Plan
    table = generate_series(Plan(family='paszota', displacement=DISPLACEMENT), Injection(),
                            seed=2, samples=6 * 3600, rate=1.0, hold_s=20.0)
    samples = HealthSamples.from_table(table)
    assert samples.temperature is not None
    factors, alarms = [], []
    for data in (samples, dataclasses.replace(samples, temperature=None)):
        monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
        alarms.append(_run(data, monitor, 3600))
        factors.append(np.array([p.bin_factor for p in monitor.pop_points()]))
    assert alarms == [[], []]
    assert np.max(np.abs(factors[0] - factors[1])) < 0.01


@pytest.mark.parametrize('case_measured', [True, False])
def test_a_leak_to_the_case_is_found_and_named_from_the_case_or_outlet_pressure(
        case_measured: bool) -> None:
    """
    A seal passing k p to the case from 1 h on (+25 % of the losses at this motor's loads).

    With the case pressure measured the leak follows it; without, the case drains to the
    outlet and its pressure drives the leak: either way one change alarm within 5 min,
    named a leak (external leakage) on the pressure that drives it (the outlet's must move:
    a leak on a constant pressure is a flow offset, and is named so).
    """
    samples = recording(1.6, seed=5, rate_hz=2.0)
    # the outlet's pressure moves (the drop kept): a leak on a constant one is an offset
    lift = 1.0e6 * (1.0 + np.sin(2 * np.pi * samples.time / 71.0))
    samples = dataclasses.replace(samples, p_in=samples.p_in + lift, p_out=samples.p_out + lift)
    p_case = 0.3 * samples.p_out + 0.2e6 * (1.0 + np.sin(2 * np.pi * samples.time / 97.0))
    drive = p_case if case_measured else samples.p_out
    baseline = Baseline.for_family('paszota', DISPLACEMENT)
    model = baseline.model
    loss = float(np.mean(model.absorbency(samples.speed, dp=samples.p_in - samples.p_out,
                                          errors='mask').flow
                         - model.geometry.displacement * samples.speed))
    k = 0.25 * loss / float(np.mean(drive))
    flow = samples.flow + np.where(samples.time >= 3600.0, k * drive, 0.0)
    data = dataclasses.replace(samples, flow=flow, p_case=p_case if case_measured else None)
    monitor = HealthMonitor(baseline, dataclasses.replace(QUIET, explain=True))
    _run(data, monitor)
    (alarm,) = monitor.snapshot().alarms
    assert alarm.kind == 'change' and 3600.0 <= alarm.time_s <= 3600.0 + 300.0
    assert alarm.after > alarm.before
    driver = 'p_case' if case_measured else 'p_out'
    assert alarm.what.startswith('leak (external leakage)'), alarm.what
    assert f'external_leakage({driver})' in alarm.what, alarm.what


@pytest.fixture(scope='module')
def small_steps() -> dict[str, str]:
    """What-changed on +10 % of the losses as a flowmeter gain, a case leak or the leakage."""
    from satmotor_ros.identify.health.explain import explain_change
    from satmotor_ros.identify.synthetic import base_model, generate_series, Injection, Plan
    plan = Plan(family='paszota', displacement=DISPLACEMENT)
    table = generate_series(plan, [Injection()], seed=1, samples=7200, rate=2.0, hold_s=20.0)
    samples = dataclasses.replace(HealthSamples.from_table(table), p_case=None)
    baseline = Baseline(base_model(plan))
    model = baseline.model
    loss = (model.absorbency(samples.speed, dp=samples.p_in - samples.p_out).flow
            - model.geometry.displacement * samples.speed)
    after = samples.time >= 1800.0
    size = 0.1 * float(np.mean(loss[after]))  # [m^3/s]
    flows = {'internal leakage': samples.flow + np.where(after, 0.1 * loss, 0.0)}
    for sign, way in ((1.0, ''), (-1.0, ' down')):  # a leak that shrinks, a gain below 1
        flows['case leak' + way] = samples.flow + np.where(
            after, sign * size * samples.p_out / float(np.mean(samples.p_out[after])), 0.0)
        flows['flow sensor gain' + way] = samples.flow * np.where(
            after, 1.0 + sign * size / float(np.mean(samples.flow[after])), 1.0)
    answers = {}
    for kind, flow in flows.items():
        stepped = dataclasses.replace(samples, flow=flow)
        answers[kind] = explain_change(stepped.take(~after), stepped.take(after), baseline)
    return answers


@pytest.mark.parametrize(('kind', 'named'), [('flow sensor gain', 'sensor gain'),
                                             ('case leak', 'external_leakage(p_out)'),
                                             ('internal leakage', 'wear: the')])
def test_what_changed_tells_a_small_gain_a_leak_and_a_wear_apart(
        small_steps: dict[str, str], kind: str, named: str) -> None:
    """
    Each kind is named alone, not as another.

    The selection asks for no effect at +10 %; weighed against each other on both sides of
    the change the kinds part (the fallback named each 'wear').
    """
    answer = small_steps[kind]
    assert named in answer and ' or ' not in answer.replace('flow or speed', ''), answer


@pytest.mark.parametrize('kind', ['case leak', 'flow sensor gain'])
def test_what_changed_names_the_way_a_leak_or_a_gain_moved(small_steps: dict[str, str],
                                                           kind: str) -> None:
    """
    A leak that grows and one that shrinks, a gain above and below 1 (review F5).

    Named 'up' and 'down' (a gain by how much), or not named that effect at all; never the
    same words for both ways.
    """
    up, down = small_steps[kind], small_steps[kind + ' down']
    if kind == 'case leak':
        high, low = ('leak (external leakage) up',), ('leak (external leakage) down',)
        assert 'external_leakage(p_out)' in up, up
    else:  # a flowmeter reading high fits as a speed sensor reading low
        high = ('flow sensor gain up', 'flow up', 'speed sensor gain down', 'speed down')
        low = ('flow sensor gain down', 'flow down', 'speed sensor gain up', 'speed up')
    assert any(w in up for w in high) and not any(w in up for w in low), up
    assert down == 'unexplained' or (any(w in down for w in low)
                                     and not any(w in down for w in high)), down

# SPDX-License-Identifier: Apache-2.0
"""The speed controller's law on the plant, without ROS: tracking, anti-windup, feed-forward."""

import dataclasses
import math

import numpy as np
import pytest

from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, MPA, RPM
from satmotor_ros.plant import PlantError
from satmotor_ros.plant.controller import ControllerParams, SpeedController
from satmotor_ros.plant.scenario import (Cycle, default_cycle, run_closed_loop, Segment,
                                         step_metrics)

MODELS = {name: MotorModel.default(name) for name in ('oil', 'water')}


def test_model_feedforward_is_the_absorbency_at_the_setpoint_and_measured_pressure():
    """Q_ff = Q(n_set, dp) of eq. (36) with the channel drop solved; naive = q_t n_set."""
    model = MODELS['water']
    law = SpeedController(ControllerParams(feedforward='model'), model)
    assert law.feedforward(80.0, 15.0 * MPA) == pytest.approx(
        float(model.absorbency(80.0, 15.0 * MPA).flow), rel=1e-12)
    naive = SpeedController(ControllerParams(feedforward='naive'), model)
    assert naive.feedforward(80.0, 15.0 * MPA) == model.geometry.displacement * 80.0
    beyond = law.feedforward(80.0, 80.0 * MPA)  # beyond the model's limit: naive, counted
    assert beyond == model.geometry.displacement * 80.0 and law.feedforward_fallbacks == 1
    assert SpeedController(ControllerParams(feedforward='none'), model).feedforward(
        80.0, 1.0) == 0.0


@pytest.mark.parametrize('liquid', ['oil', 'water'])
@pytest.mark.parametrize('feedforward', ['model', 'naive', 'none'])
def test_pi_reaches_every_setpoint_without_steady_state_error(liquid, feedforward):
    """Integral action: zero steady-state error after each step of the demo cycle."""
    run = run_closed_loop(MODELS[liquid], default_cycle(), ControllerParams(
        feedforward=feedforward))
    for m in step_metrics(run.time, run.setpoint, run.speed, run.load):
        assert abs(m.steady_state_error) < 0.005 * m.target, m


@pytest.mark.parametrize('liquid', ['oil', 'water'])
def test_feedforward_cuts_rise_time_and_iae_against_the_pi_alone(liquid):
    """With the inverse model in front, steps rise >5x faster and the IAE drops >2x."""
    def run(ff):
        r = run_closed_loop(MODELS[liquid], default_cycle(), ControllerParams(feedforward=ff))
        return step_metrics(r.time, r.setpoint, r.speed, r.load)
    with_ff, alone = run('model'), run('none')
    rise = [(a.rise_time, b.rise_time) for a, b in zip(with_ff, alone)
            if not math.isnan(b.rise_time)]
    assert rise and all(a * 5.0 < b for a, b in rise)
    assert sum(m.iae for m in with_ff) * 2.0 < sum(m.iae for m in alone)


def test_model_feedforward_rejects_load_steps_on_water_better_than_naive():
    """Water leaks more under load: the model's feed-forward compensates it at once."""
    def load_iae(ff):
        r = run_closed_loop(MODELS['water'], default_cycle(), ControllerParams(feedforward=ff))
        return sum(m.iae for m in step_metrics(r.time, r.setpoint, r.speed, r.load)
                   if m.start == m.target)
    assert load_iae('model') < 0.9 * load_iae('naive')


def test_anti_windup_recovers_at_once_after_saturation():
    """Without anti-windup the pump stays at its limit long after the set-point drops."""
    cycle = Cycle((Segment(3.0, 4000.0 * RPM, 10.0), Segment(3.0, 600.0 * RPM, 10.0)))
    params = ControllerParams(feedforward='none', flow_max=40.0 * LPM)

    def recovery_iae(anti_windup):
        r = run_closed_loop(MODELS['oil'], cycle,
                            dataclasses.replace(params, anti_windup=anti_windup))
        assert float(np.max(r.flow_command)) == pytest.approx(40.0 * LPM)
        after = r.time >= 3.0
        return float(np.sum(np.abs(r.setpoint[after] - r.speed[after])) * 0.01)
    with_aw, without = recovery_iae(True), recovery_iae(False)
    assert with_aw * 5.0 < without


def test_law_refuses_non_finite_inputs_and_bad_parameters():
    """A NaN measurement raises PlantError naming it; bad gains are refused on construction."""
    law = SpeedController(ControllerParams(), MODELS['oil'])
    with pytest.raises(PlantError, match='speed=nan'):
        law.update(10.0, math.nan, 1.0e6, 0.01)
    with pytest.raises(PlantError, match='feedforward'):
        ControllerParams(feedforward='psychic')
    with pytest.raises(PlantError, match='kp'):
        ControllerParams(kp=-1.0)


def test_step_metrics_on_a_known_first_order_response():
    """A first-order lag of 0.1 s: rise = 0.1 ln 9 s, no overshoot, IAE = step * 0.1 s."""
    t = np.arange(0.0, 2.0, 1e-4)
    setpoint = np.full_like(t, 10.0)
    speed = 10.0 * (1.0 - np.exp(-t / 0.1))
    (m,) = step_metrics(t, setpoint, speed)
    assert m.rise_time == pytest.approx(0.1 * math.log(9.0), rel=1e-2)
    assert m.overshoot == 0.0
    assert m.iae == pytest.approx(1.0, rel=1e-2)
    assert m.steady_state_error == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize('feedforward', ['model', 'none'])
def test_a_negative_setpoint_drives_the_motor_backwards_as_a_positive_one_forwards(feedforward):
    """Signed set-points: the reverse steps are tracked as the forward ones, mirrored."""
    steps = (Segment(2.0, 600.0 * RPM, 0.0), Segment(2.0, -600.0 * RPM, 0.0),
             Segment(2.0, -1000.0 * RPM, 0.0), Segment(2.0, 300.0 * RPM, 0.0))
    run = run_closed_loop(MODELS['oil'], Cycle(steps), ControllerParams(feedforward=feedforward))
    for m in step_metrics(run.time, run.setpoint, run.speed, run.load):
        assert abs(m.steady_state_error) < 0.005 * abs(m.target), m
    asked = np.concatenate(([0.0], run.setpoint[:-1]))  # a command reaches the plant 1 late
    backwards = run.setpoint < 0.0
    assert np.all(run.flow_command[asked < 0.0] <= 0.0)  # the mirrored range [-flow_max, 0]
    assert np.all(run.flow_command[asked > 0.0] >= 0.0)
    end = run.time >= 5.5
    assert np.all(run.speed[end & backwards] < -0.99 * 1000.0 * RPM)


def test_the_flow_range_mirrors_for_a_negative_setpoint():
    law = SpeedController(ControllerParams(flow_min=1.0 * LPM, flow_max=40.0 * LPM),
                          MODELS['water'])
    assert law.flow_range(10.0) == (1.0 * LPM, 40.0 * LPM)
    assert law.flow_range(-10.0) == (-40.0 * LPM, -1.0 * LPM)
    command = law.update(-3000.0 * RPM, 0.0, 0.0, 0.01)  # far out of reach: saturated
    assert command == -40.0 * LPM and law.saturated

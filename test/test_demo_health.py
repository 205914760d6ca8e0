# SPDX-License-Identifier: Apache-2.0
"""The demo's health section: the monitor over a healthy run's bag, then a leaking run's."""

import json

import numpy as np

from satmotor_ros.cli._demo_health import demo_settings, HEALTH_DIR, health_section
from satmotor_ros.identify.synthetic import generate_series, Injection, Plan, write_bag_of
from satmotor_ros.model.units import LPM, MPA

LEAK = 1.5 * LPM / MPA  # k_ex [m^3/(s*Pa)]: a few l/min at the case pressures of the plan


def _bags(tmp_path):
    plan = Plan(liquid='water', temperature_jitter=0.0)
    bags = []
    for name, injection in (('water_model', Injection()),
                            ('water_model_loop', Injection('external_leakage', LEAK, 'p_case'))):
        table = generate_series(plan, [injection], seed=3, samples=3000, rate=100.0,
                                hold_s=3.0)
        write_bag_of(tmp_path / 'bags' / name, table)
        bags.append(tmp_path / 'bags' / name)
    return bags


def test_demo_health_section_flags_the_leaking_run_and_writes_the_monitor_outputs(tmp_path):
    """Learned on the healthy run: no alarm there, a change once the leak runs; files written."""
    bags = _bags(tmp_path)
    lines = health_section(tmp_path, 'water', bags, {'effects.external_leakage': LEAK})
    text = '\n'.join(lines)
    doc = json.loads((tmp_path / HEALTH_DIR / 'monitor.json').read_text())
    start = doc['recordings'][1]['start_s']
    assert doc['alarms'] and doc['alarms'][0]['kind'] == 'change'
    assert all(a['time_s'] >= start for a in doc['alarms'])  # none on the healthy run
    assert doc['alarms'][0]['after'] > doc['alarms'][0]['before']
    assert '## Health over the runs' in text and '| change |' in text
    assert f'`external_leakage = {LEAK:g}`' in text
    assert f'`water_model_loop` {start:.0f}-' in text
    assert '](health/report.md)' in text
    for name in ('report.md', 'health.csv', 'leakage_factor.png'):
        assert (tmp_path / HEALTH_DIR / name).stat().st_size > 0, name


def test_demo_settings_learn_on_most_of_the_first_run_in_one_second_bins():
    """The time scales follow the run's length; the false-alarm interval stays the default."""
    settings = demo_settings(24.0)
    assert np.isclose(settings.learn_hours * 3600.0, 0.8 * 24.0)
    assert settings.bin_s == 1.0 and settings.window_s == 5.0
    assert settings.false_alarm_hours == 1000.0

# SPDX-License-Identifier: Apache-2.0
"""``satmotor demo``: a short real run over ROS leaves bags with every topic and a report."""

import json
from pathlib import Path
import re

import pytest
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_typestore, Stores

from satmotor_ros.cli.demo import command
from satmotor_ros.cli.main import main
from satmotor_ros.model.units import RPM

pytestmark = [pytest.mark.ros, pytest.mark.slow]

PNG = b'\x89PNG\r\n\x1a\n'


@pytest.fixture(scope='module')
def demo_run(tmp_path_factory):
    """
    Run the demo on water for its default 24 s of simulated time, with an injected effect.

    One run serves the report, the bags and the closing of the loop: the loop run's own
    leak (2e-11) replaces the injected 2e-12, so its calibration is the default demo's.
    """
    out = tmp_path_factory.mktemp('demo') / 'out'
    code = command(liquid='water', duration='24', effect=['external_leakage=2e-12'],
                   out=str(out), quiet=True)
    return code, out


def test_demo_writes_a_report_with_its_plots(demo_run):
    """report.md names the effect, holds the metrics table and links real PNGs."""
    code, out = demo_run
    assert code == 0
    report = (out / 'report.md').read_text()
    assert 'external_leakage = 2e-12' in report
    assert '| water | model |' in report and '| water | none (PI alone) |' in report
    assert 'Prediction from the motor_model node' in report
    assert '## Closing the loop' in report
    assert 'points held 4 s each' in report  # 1.5 x 24 s over nine points, as it ran
    # the injected leakage takes k p_case / q_t = 0.55 rpm the model does not know about
    bias = float(re.search(r'has a median of (-?[0-9.]+) rpm', report).group(1))
    assert -1.0 < bias < -0.3
    for name in ('tracking_water.png', 'prediction_water.png', 'losses_water.png'):
        assert f']({name})' in report
        data = (out / name).read_bytes()
        assert data.startswith(PNG) and len(data) > 20_000, name


@pytest.mark.parametrize('run', ['water_model', 'water_none'])
def test_demo_bags_hold_every_topic_at_its_rate(demo_run, run):
    """Each MCAP bag has every topic; joint_states at 100 Hz; the speed reaches the set-point."""
    _, out = demo_run
    typestore = get_typestore(Stores.ROS2_KILTED)
    with Reader(out / 'bags' / run) as reader:
        assert list((out / 'bags' / run).glob('*.mcap'))
        counts = {c.topic: c.msgcount for c in reader.connections}
        for topic in ('/flow_command', '/inlet_pressure', '/outlet_pressure', '/case_pressure',
                      '/flow_measured', '/joint_states', '/fluid_temperature', '/load_torque',
                      '/speed_setpoint', '/diagnostics', '/clock', '/predicted_joint_state',
                      '/speed_residual', '/losses/total', '/losses/flat_clearance'):
            assert counts.get(topic, 0) > 0, topic
        assert counts['/joint_states'] == pytest.approx(2400, abs=20)
        joints = [c for c in reader.connections if c.topic == '/joint_states']
        last = None
        for connection, _, raw in reader.messages(connections=joints):
            last = typestore.deserialize_cdr(raw, connection.msgtype)
    assert last.velocity[0] == pytest.approx(900.0 * RPM, rel=0.02)  # the last set-point


def test_demo_refuses_bad_options_in_one_line(tmp_path, capsys):
    """A bad effect, duration or an existing output: exit 1 and one line naming it."""
    assert main(['demo', '--effect', 'bogus=1', '--out', str(tmp_path / 'a')]) == 1
    assert main(['demo', '--duration', '-3', '--out', str(tmp_path / 'b')]) == 1
    assert main(['demo', '--effect', 'clearance_wear=1', '--out', str(tmp_path / 'c')]) == 1
    (tmp_path / 'd' / 'bags' / 'oil_model').mkdir(parents=True)
    assert main(['demo', '--liquid', 'oil', '--out', str(tmp_path / 'd')]) == 1
    lines = [line for line in capsys.readouterr().err.splitlines() if line]
    assert len(lines) == 4
    assert 'bogus' in lines[0] and '-3' in lines[1] and 'clearance_wear' in lines[2]
    assert 'exists' in lines[3]
    assert not Path(tmp_path / 'a').exists()


def test_demo_closes_the_loop_on_its_own_recording(demo_run):
    """The default demo also calibrates a run with a leak the model lacks, and names it."""
    code, out = demo_run
    assert code == 0
    report = (out / 'report.md').read_text()
    section = report[report.index('## Closing the loop'):]
    assert '`external_leakage = 2e-11`' in section and 'points held 4 s each' in section
    assert '](loop/report.md)' in section and '](loop/residuals.png)' in section
    assert 'Data: `bags/water_model_loop`' in (out / 'loop' / 'report.md').read_text()
    result = json.loads((out / 'loop' / 'calibration.json').read_text())
    first = result['effects'][0]
    assert first['effect'] == 'external_leakage'
    assert abs(first['coefficient'] / 2e-11 - 1.0) < 0.05
    covered = first['ci95'][0] <= 2e-11 <= first['ci95'][1]
    assert ('It named the injected `external_leakage`' in section) == covered
    assert ('does not cover the injected 2e-11: not named' in section) == (not covered)
    # the case pressure steps separate the leak from the speed-driven losses
    r = float(re.search(r'with `\w+`: r = ([-+0-9.]+) \(separated\)', section).group(1))
    assert abs(r) < 0.95
    assert result['error_after']['rmse_lpm'] < 0.3 * result['error_before']['rmse_lpm']
    assert (out / 'loop' / 'residuals.png').read_bytes().startswith(PNG)
    assert (out / 'bags' / 'water_model_loop' / 'metadata.yaml').is_file()
    health = report[report.index('## Health over the runs'):]
    assert '`water_model`' in health and '`water_model_loop`' in health
    monitor = json.loads((out / 'health' / 'monitor.json').read_text())
    assert monitor['n_samples'] > 1000 and monitor['recordings'][1]['data'] == 'water_model_loop'


def test_demo_without_the_loop(tmp_path):
    out = tmp_path / 'out'
    assert command(liquid='water', duration='3', effect=[], out=str(out), quiet=True,
                   no_loop=True) == 0
    assert '## Closing the loop' not in (out / 'report.md').read_text()
    assert not (out / 'loop').exists() and not (out / 'bags' / 'water_model_loop').exists()

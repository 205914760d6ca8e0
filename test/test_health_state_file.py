# SPDX-License-Identifier: Apache-2.0
"""
A state file edited by hand or cut short is refused in one line naming the field (review F7).

It used to come back as a TypeError or KeyError from deep inside the monitor (the node and
``satmotor monitor`` crashed), or to be taken and fail on the next sample. The estimator's
:meth:`HealthMonitor.resume` is the one check; the node starts afresh on it without writing
over the file (``test_motor_monitor_state_rules.py``), the command exits 1 and writes nothing.
"""

from __future__ import annotations

from collections.abc import Callable
import json
from pathlib import Path
from typing import Any

from health_data import DISPLACEMENT, recording
import numpy as np
import pytest

from satmotor_ros.cli.main import main
from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.health import Baseline, HealthMonitor, HealthSettings
from satmotor_ros.identify.table import write_csv

SETTINGS = HealthSettings(learn_hours=0.1)


def _baseline() -> Baseline:
    return Baseline.for_family('paszota', DISPLACEMENT)


@pytest.fixture(scope='module')
def saved(tmp_path_factory: pytest.TempPathFactory) -> str:
    """Save a state with a change alarm and raw samples kept; return its text."""
    samples = recording(0.3, seed=3, rate_hz=2.0,
                        scale=lambda t: np.where(t >= 700.0, 1.5, 1.0))
    monitor = HealthMonitor(_baseline(), SETTINGS, lambda before, after, baseline: 'a step')
    monitor.update(samples)
    assert monitor.alarms and monitor.recent and monitor.window  # every part is there
    path = tmp_path_factory.mktemp('state') / 'health.json'
    monitor.save(path)
    return path.read_text()


def _set(*keys: Any, value: Any) -> Callable[[Any], None]:
    def edit(doc: Any) -> None:
        for key in keys[:-1]:
            doc = doc[key]
        doc[keys[-1]] = value
    return edit


def _drop(*keys: Any) -> Callable[[Any], None]:
    def edit(doc: Any) -> None:
        for key in keys[:-1]:
            doc = doc[key]
        del doc[keys[-1]]
    return edit


EDITS = {
    'n_samples': _set('n_samples', value='12 000'),
    'cusum: missing': _drop('cusum'),
    'settings.bin_s': _set('settings', 'bin_s', value='ten'),
    'settings.reference_speed': _set('settings', 'reference_speed', value='fast'),
    'settings.colour: not a field': _set('settings', 'colour', value=1),
    'trend.sw': _set('trend', 'sw', value=None),
    'open_bin': _set('open_bin', value={'__array__': [1.0]}),
    "alarms[0].kind = 'boom'": _set('alarms', 0, 'kind', value='boom'),
    'alarms[0].what: missing': _drop('alarms', 0, 'what'),
    'window[0]': _set('window', 0, value=[1.0, 2.0]),
    'pending = 7': _set('pending', value=7),
    'recent[0].flow: 3 values': _set('recent', 0, 'flow', value={'__array__': [1.0, 2.0, 3.0]}),
    'learning': _set('learning', value='yes'),
    'mine: not a field': _set('mine', value=True),
}


@pytest.mark.parametrize('field', list(EDITS))
def test_a_hand_edited_state_is_refused_naming_the_field(saved: str, tmp_path: Path,
                                                         field: str) -> None:
    """One DataError line with the file and the field; never a TypeError or KeyError."""
    doc = json.loads(saved)
    EDITS[field](doc)
    path = tmp_path / 'edited.json'
    path.write_text(json.dumps(doc))
    with pytest.raises(DataError) as err:
        HealthMonitor.resume(path, _baseline())
    text = str(err.value)
    assert text.startswith(f'{path}: ') and field in text and '\n' not in text, text


def test_a_state_cut_short_is_refused(saved: str, tmp_path: Path) -> None:
    """A disk that filled up mid-write (not ours: ours renames a whole file into place)."""
    path = tmp_path / 'cut.json'
    path.write_text(saved[:len(saved) // 2])
    with pytest.raises(DataError, match='not a health state .cut short'):
        HealthMonitor.resume(path, _baseline())


def test_a_state_saved_before_a_reason_was_counted_is_resumed(saved: str,
                                                              tmp_path: Path) -> None:
    """No 'implausible' count, no 'carry': filled in (0), the rest taken as it was."""
    doc = json.loads(saved)
    del doc['skipped']['implausible'], doc['carry']
    path = tmp_path / 'older.json'
    path.write_text(json.dumps(doc))
    monitor = HealthMonitor.resume(path, _baseline())
    assert monitor.skipped['implausible'] == 0 and monitor.carry.tolist() == [0.0] * 8
    assert monitor.n_samples == doc['n_samples'] and len(monitor.alarms) == 1
    monitor.update(recording(0.02, seed=4, rate_hz=2.0, t0=monitor.t_last + 0.5))
    assert monitor.snapshot().n_samples > doc['n_samples']


def test_satmotor_monitor_refuses_it_in_one_line_and_writes_nothing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A state the command saved, edited: exit 1, the field on stderr, the file kept, no --out."""
    samples = recording(0.05, seed=5, rate_hz=2.0)
    data = tmp_path / 'day.csv'
    write_csv(data, {'time': ('s', samples.time), 'speed': ('rad/s', samples.speed),
                     'flow': ('m^3/s', samples.flow), 'p_in': ('Pa', samples.p_in),
                     'p_out': ('Pa', samples.p_out)})
    state = tmp_path / 'health.json'

    def run(out: str) -> int:
        return main(['monitor', str(data), '--out', str(tmp_path / out), '--state', str(state),
                     '--liquid', 'oil', '--family', 'paszota', '--displacement',
                     f'{DISPLACEMENT * 2 * np.pi * 1e6:.9g}', '--no-explain'])
    assert run('first') == 0
    doc = json.loads(state.read_text())
    EDITS['n_samples'](doc)
    state.write_text(json.dumps(doc))
    before = state.read_bytes()
    capsys.readouterr()
    code = run('second')
    err = capsys.readouterr().err.strip()
    assert code == 1 and 'n_samples' in err and len(err.splitlines()) == 1, err
    assert state.read_bytes() == before and not (tmp_path / 'second').exists()

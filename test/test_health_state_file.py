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
from satmotor_ros.identify.health.state import check_state, compatible, template
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


def _array(n: int, value: float = 1.0) -> dict[str, list[float]]:
    return {'__array__': [value] * n}


def _length(doc: dict[str, Any]) -> int:
    return len(doc['recent'][0]['time']['__array__'])


LONG = 'x' * 45
"""A value whose repr the message cuts at 40 characters."""

# edit -> the message after '<file>: ' exactly ({n}: the times in recent[0])
REFUSED = {
    'int as bool': (_set('n_samples', value=True), 'n_samples = True: need a whole number'),
    'int as float': (_set('n_samples', value=1.5), 'n_samples = 1.5: need a whole number'),
    'bool as int': (_set('learning', value=1), 'learning = 1: need true or false'),
    'float as bool': (_set('var_a', value=True), 'var_a = True: need a number'),
    'float as str': (_set('var_a', value=LONG), f"var_a = '{'x' * 36}...: need a number"),
    'float, 40 characters': (_set('var_a', value='x' * 38),
                             f"var_a = '{'x' * 38}': need a number"),
    'float, 41 characters': (_set('var_a', value='x' * 39),
                             f"var_a = '{'x' * 36}...: need a number"),
    'str as int': (_set('what_changed', value=3), 'what_changed = 3: need a string'),
    'mapping as list': (_set('cusum', value=[]), 'cusum = []: need a mapping'),
    'mapping key missing': (_drop('cusum', 'up'),
                            'cusum.up: missing (a truncated or edited state?)'),
    'mapping key unknown': (_set('cusum', 'mine', value=1.0),
                            'cusum.mine: not a field of the health state'),
    'array too short': (_set('open_bin', value=_array(1)), 'open_bin = 1 values: need 8 numbers'),
    'array as list': (_set('open_bin', value=[1.0] * 8),
                      'open_bin = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]: need 8 numbers'),
    'array of booleans': (_set('open_bin', value={'__bool__': [True] * 8}),
                          'open_bin = 8 values: need 8 numbers'),
    'list as number': (_set('last_flow_rate_x', value=3.0),
                       'last_flow_rate_x = 3.0: need a list'),
    'list too short': (_set('last_flow_rate_x', value=[1.0]),
                       'last_flow_rate_x = [1.0]: need 2 entries'),
    'list item': (_set('last_flow_rate_x', value=[1.0, 'x']),
                  "last_flow_rate_x[1] = 'x': need a number"),
    'nested list too long': (_set('since', 'up', value=[1.0, 2.0, 3.0]),
                             'since.up = [1.0, 2.0, 3.0]: need 2 entries'),
    'rows as mapping': (_set('window', value={}), 'window = {{}}: need a list'),
    'row too short': (_set('window', 0, value=[1.0, 2.0]),
                      'window[0] = [1.0, 2.0]: need 3 numbers'),
    'row of text': (_set('window', 1, value=[1.0, 2.0, 'x']),
                    "window[1] = [1.0, 2.0, 'x']: need 3 numbers"),
    'row as number': (_set('window', 0, value=1.0), 'window[0] = 1.0: need 3 numbers'),
    'trend row': (_set('trend_bins', 0, value=[1.0] * 4),
                  'trend_bins[0] = [1.0, 1.0, 1.0, 1.0]: need 5 numbers'),
    'learn row': (_set('learn_bins', value=[[1.0] * 6, [1.0] * 5]),
                  'learn_bins[1] = [1.0, 1.0, 1.0, 1.0, 1.0]: need 6 numbers'),
    'alarm as number': (_set('alarms', 0, value=3), 'alarms[0] = 3: need a mapping'),
    'alarm field': (_set('alarms', 0, 'time_s', value='x'),
                    "alarms[0].time_s = 'x': need a number"),
    'alarm what': (_set('alarms', 0, 'what', value=3), 'alarms[0].what = 3: need a string'),
    'alarm statistic': (_set('alarms', 0, 'statistic', value=[]),
                        'alarms[0].statistic = []: need a number'),
    'noise counts': (_set('noise_rate', value=[_array(2)]),
                     'noise_rate, noise_residual: need as many blocks of each'),
    'noise as list': (_set('noise_rate', value=[[1.0]]),
                      'noise_rate[0] = [1.0]: need a list of numbers'),
    'noise of booleans': (_set('noise_residual', value=[{'__bool__': [True]}]),
                          'noise_residual[0] = 1 values: need a list of numbers'),
    'pending too high': (_set('pending', value=1),
                         "pending = 1: need -1 or an alarm's index (0 to 0)"),
    'pending too low': (_set('pending', value=-2),
                        "pending = -2: need -1 or an alarm's index (0 to 0)"),
    'acknowledged too high': (_set('acknowledged', value=2),
                              'acknowledged = 2: need 0 to 1 alarms'),
    'acknowledged too low': (_set('acknowledged', value=-1),
                             'acknowledged = -1: need 0 to 1 alarms'),
    'block as number': (_set('recent', 0, value=3), 'recent[0] = 3: need a block of samples'),
    'held block': (_set('held', value=[[]]), 'held[0] = []: need a block of samples'),
    'column unknown': (_set('recent', 0, 'colour', value=_array(1)),
                       'recent[0].colour: not a column of the samples'),
    'column missing': (_drop('recent', 0, 'time'),
                       'recent[0].time = None: need a list of numbers'),
    'column as list': (_set('recent', 0, 'p_out', value=[1.0]),
                       'recent[0].p_out = [1.0]: need a list of numbers'),
    'column of booleans': (_set('recent', 0, 'speed', value={'__bool__': [True]}),
                           'recent[0].speed = 1 values: need a list of numbers'),
    'column too short': (_set('recent', 0, 'p_in', value=_array(3)),
                         'recent[0].p_in: 3 values for {n} times'),
    'optional column too short': (_set('recent', 0, 'temperature', value=_array(2)),
                                  'recent[0].temperature: 2 values for {n} times'),
    'stale as numbers': (_set('recent', 0, 'stale', value=_array(2)),
                         'recent[0].stale = 2 values: need a list of booleans'),
    'settings as list': (_set('settings', value=[]), 'settings = []: need a mapping'),
    'settings number as bool': (_set('settings', 'bin_s', value=True),
                                'settings.bin_s = True: need a number'),
    'settings number as None': (_set('settings', 'bin_s', value=None),
                                'settings.bin_s = None: need a number'),
    'settings bool as int': (_set('settings', 'explain', value=1),
                             'settings.explain = 1: need true or false'),
}


@pytest.mark.parametrize('case', list(REFUSED))
def test_each_kind_of_edit_is_refused_in_its_own_words(saved: str, tmp_path: Path,
                                                       case: str) -> None:
    """The file, the field with its index, what it holds (cut at 40) and what it needs."""
    doc = json.loads(saved)
    edit, message = REFUSED[case]
    n = _length(doc)
    edit(doc)
    path = tmp_path / 'edited.json'
    path.write_text(json.dumps(doc))
    with pytest.raises(DataError) as err:
        HealthMonitor.resume(path, _baseline())
    assert str(err.value) == f'{path}: ' + message.format(n=n)


def _column(name: str, kind: str = '__array__') -> Callable[[Any], None]:
    def edit(doc: Any) -> None:
        block = doc['recent'][0]
        block[name] = {kind: [kind == '__bool__' or 2.0] * _length(doc)}
    return edit


def _both(*edits: Callable[[Any], None]) -> Callable[[Any], None]:
    def edit(doc: Any) -> None:
        for one in edits:
            one(doc)
    return edit


TAKEN = {
    'optional columns present': _both(_column('p_case'), _column('temperature'),
                                      _column('stale', '__bool__')),
    'optional column None': _set('recent', 0, 'temperature', value=None),
    'a held block': lambda doc: doc['held'].append(doc['recent'][0]),
    'learn rows': _set('learn_bins', value=[[1.0, 2, 3.0, 4.0, 5.0, 6.0]]),
    'noise blocks': _both(_set('noise_rate', value=[_array(3)]),
                          _set('noise_residual', value=[_array(2)])),
    'a limit alarm': _set('alarms', 0, 'kind', value='limit'),
    'pending and acknowledged at their ends': _both(_set('pending', value=0),
                                                    _set('acknowledged', value=1)),
    'a settings field None': _set('settings', 'reference_dp', value=None),
    'a settings field given as a whole number': _set('settings', 'bin_s', value=20),
    'a settings field left out': _drop('settings', 'window_s'),
    'no step_s': _drop('step_s'),
    'no trend_bins': _drop('trend_bins'),
}


@pytest.mark.parametrize('case', list(TAKEN))
def test_a_state_edited_within_its_layout_is_taken(saved: str, tmp_path: Path,
                                                   case: str) -> None:
    """What a monitor may hold, an optional column either way, an older state filled in."""
    doc = json.loads(saved)
    TAKEN[case](doc)
    path = tmp_path / 'edited.json'
    path.write_text(json.dumps(doc))
    monitor = HealthMonitor.resume(path, _baseline())
    assert monitor.n_samples == doc['n_samples']
    if case == 'a settings field given as a whole number':
        assert monitor.settings.bin_s == 20.0
    if case == 'a settings field left out':
        assert monitor.settings.window_s == HealthSettings().window_s
    if case == 'no trend_bins':
        assert list(monitor.trend_bins) == []


def test_a_settings_value_the_settings_refuse_is_named(saved: str, tmp_path: Path) -> None:
    """The settings' own check, prefixed with the file and 'settings.'."""
    doc = json.loads(saved)
    doc['settings']['bin_s'] = -1.0
    path = tmp_path / 'edited.json'
    path.write_text(json.dumps(doc))
    with pytest.raises(DataError) as err:
        HealthMonitor.resume(path, _baseline())
    with pytest.raises(DataError) as own:
        HealthSettings(bin_s=-1.0)
    assert str(err.value) == f'{path}: settings.{own.value}'


def test_compatible_fills_in_only_what_an_older_state_lacks() -> None:
    """step_s 0, no trend bins, carry as zeros like the open bin, every skip reason counted."""
    old = compatible({'open_bin': np.arange(3.0), 'skipped': {'stale': 4}})
    assert old['step_s'] == 0.0 and old['trend_bins'] == []
    assert old['carry'].tolist() == [0.0, 0.0, 0.0]
    assert old['skipped']['stale'] == 4 and old['skipped']['implausible'] == 0
    carry = np.ones(3)
    new = compatible({'open_bin': np.arange(3.0), 'carry': carry, 'step_s': 0.5,
                      'trend_bins': [[1.0] * 5], 'skipped': 'none'})
    assert new['carry'] is carry and new['step_s'] == 0.5 and new['trend_bins'] == [[1.0] * 5]
    assert new['skipped'] == 'none'  # left for the check to refuse
    assert 'carry' not in compatible({'open_bin': [0.0]})  # not an array: the check refuses


def test_template_gives_the_layout_json_reads_back() -> None:
    """Tuples as lists, arrays of floats or booleans, numpy scalars as Python ones."""
    like = template({'a': (np.float64(1.5), np.int64(2)), 'b': {'c': np.arange(2)},
                     'd': np.array([True]), 'e': 'text'})
    assert like == {'a': [1.5, 2], 'b': {'c': like['b']['c']}, 'd': like['d'], 'e': 'text'}
    assert [type(x) for x in like['a']] == [float, int]
    assert like['b']['c'].dtype == float and like['b']['c'].tolist() == [0.0, 1.0]
    assert like['d'].dtype == bool and like['d'].tolist() == [True]


def test_check_state_refuses_what_a_resume_cannot_reach() -> None:
    """Not a mapping at all; an entry in a list the layout holds none of."""
    like = {'alarms': [], 'pending': -1, 'acknowledged': 0, 'noise_rate': [],
            'noise_residual': [], 'mine': []}
    with pytest.raises(DataError) as err:
        check_state([], like, 'f')  # type: ignore[arg-type]
    assert str(err.value) == 'f: the state = []: need a mapping'
    with pytest.raises(DataError) as err:
        check_state({**like, 'mine': [1.0]}, like, 'f')
    assert str(err.value) == 'f: mine[0] = 1.0: need nothing (a fresh state holds none)'
    check_state(dict(like), like, 'f')  # the layout itself is taken

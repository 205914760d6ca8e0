# SPDX-License-Identifier: Apache-2.0
"""
Hostile inputs for the property tests and ``make fuzz``: effect files, column mappings, logs.

Each generator starts from inputs that work (the effect blocks ``satmotor calibrate`` writes,
a mapping of the MBARI kind) and mutates them: valid, edge and malformed alike. Each checker
runs one input through the code a user or a node reaches and returns the outcome, ``'value'``,
``'flagged'`` (a value with a status or a note that says what is wrong with it) or
``'one line'`` (an error of one line naming what is wrong); anything else (a traceback, a
message of several lines, a non-finite number with an OK status, a user's file touched) fails
with an AssertionError that names the input.
"""

from collections.abc import Iterator
import contextlib
import copy
import io
import json
import math
from pathlib import Path
import signal
import threading

from hypothesis import strategies as st
import numpy as np

from satmotor_ros.cli import main
from satmotor_ros.identify.columns import FIELDS, mapping_from_dict, read_log
from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.synthetic import generate, Injection, Plan
from satmotor_ros.identify.table import BAD_CELLS, IMPOSSIBLE
from satmotor_ros.identify.textfile import SANITY
from satmotor_ros.model import ModelError, PointStatus
from satmotor_ros.model.io.config import default_config_path
from satmotor_ros.model.units import LPM, MPA, PSI, RPM
from satmotor_ros.options import MotorOptions
import yaml

OUTCOMES = ('value', 'flagged', 'one line')
"""What every input must end in."""

EFFECTS = {
    'external_leakage': {'regressor': 'p_case', 'coefficient': 7e-12},
    'viscosity_temperature': {'coefficient': 3.0, 'law': 'walther',
                              'reference_temperature': 40.0, 'reference_viscosity': 4e-5},
    'clearance_wear': {'coefficient': 1e-9, 'regressor': 'time', 'reference': 0.0},
    'flow_sensor_offset': {'coefficient': 4e-6},
    'flow_sensor_gain': {'coefficient': 0.01},
    'speed_sensor_gain': {'coefficient': -0.01},
    'channel:aux': {'coefficient': 1e-6, 'reference': 0.5},
    'reverse_loss': {'coefficient': 1e-13},
    'term:dp^2.2*n': {'coefficient': 1.7e-24, 'exponents': {'dp': 2.23, 'n': 1.04}},
    'threshold:dp': {'coefficient': 6.8e-12, 'reference': 18e6, 'exponent': 1.0},
    'threshold:dp@negative': {'coefficient': 6.8e-12, 'reference': 18e6, 'exponent': 1.0,
                              'direction': 'negative'},
}
"""Effect blocks as a calibrated ``coefficients.yaml`` holds them, each valid on its own."""

ODD_NUMBERS = (0.0, -0.0, 1.0, -1.0, 1e-300, 5e-324, 1e300, -1e300, 1e308, math.inf,
               -math.inf, math.nan, 2.0 ** 63, 10 ** 40)
ODD_VALUES = ('', 'x', 'nan', '1e400', None, True, [], {}, [1.0, 2.0], {'dp': 1.0})
ID_ALPHABET = 'dpn^.*0123456789:@ -_abcegikrt'
POINTS = ((20 * LPM, 10 * MPA), (0.5 * LPM, 24 * MPA), (-20 * LPM, 10 * MPA),
          (20 * LPM, -10 * MPA), (0.0, 0.0), (60 * LPM, 0.1 * MPA))


SECONDS = 120
"""Longest one input may take; past it the input hangs (a FIFO read, a runaway fit), [s]."""


@contextlib.contextmanager
def bounded(what: str, seconds: int = SECONDS) -> Iterator[None]:
    """Fail an input that takes longer than `seconds` (SIGALRM; the main thread only)."""
    def hang(signum: int, frame: object) -> None:
        raise AssertionError((what, f'no end within {seconds} s'))
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGALRM, hang)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def one_line(message: str, what: str) -> None:
    """Fail unless `message` is one line that says something, without a traceback."""
    text = message.strip()
    assert text and '\n' not in text and 'Traceback' not in text, (what, message)


def _number() -> st.SearchStrategy:
    return st.one_of(st.sampled_from(ODD_NUMBERS), st.floats(allow_nan=True),
                     st.integers(-10 ** 6, 10 ** 6))


def _value() -> st.SearchStrategy:
    return st.one_of(_number(), st.sampled_from(ODD_VALUES), st.text(max_size=12))


@st.composite
def effect_blocks(draw: st.DrawFn) -> dict:
    """Draw an ``effects:`` block: one to three calibrated effects, each perhaps mutated."""
    names = draw(st.lists(st.sampled_from(sorted(EFFECTS)), min_size=1, max_size=3,
                          unique=True))
    block = {}
    for name in names:
        body = copy.deepcopy(EFFECTS[name])
        for _ in range(draw(st.sampled_from((0, 0, 1, 1, 2, 3)))):
            action = draw(st.sampled_from(('value', 'drop', 'add', 'id', 'expression',
                                           'direction')))
            keys = sorted(body)
            if action == 'value' and keys:
                body[draw(st.sampled_from(keys))] = draw(_value())
            elif action == 'drop' and keys:
                body.pop(draw(st.sampled_from(keys)))
            elif action == 'add':
                body[draw(st.sampled_from(('unknown', 'exponent', 'reference', 'direction',
                                           'regressor', 'exponents')))] = draw(_value())
            elif action == 'id':
                kind = name.partition(':')[0].partition('@')[0]
                name = kind + draw(st.sampled_from(('', ':', '@'))) + draw(
                    st.text(ID_ALPHABET, max_size=10))
            elif action == 'expression':  # a term's dp^a*n^b with a mangled power
                name = 'term:' + '*'.join(
                    draw(st.sampled_from(('dp', 'n', 'x'))) + draw(st.sampled_from(('', '^')))
                    + draw(st.text('0123456789.e-+', max_size=5))
                    for _ in range(draw(st.integers(1, 2))))
            elif action == 'direction':
                name = name.partition('@')[0] + '@' + draw(
                    st.sampled_from(('positive', 'negative', 'both', 'up', '')))
        block[name] = body
    return block


def motor_doc(effects: dict) -> dict:
    """Return the packaged motor with `effects` in its oil set."""
    doc = yaml.safe_load(default_config_path('sm075_25.yaml').read_text(encoding='utf-8'))
    oil = doc['coefficient_sets']['oil']
    oil['effects'] = effects
    leak = effects.get('external_leakage')
    if isinstance(leak, dict) and 'coefficient' in leak:  # eq. (24) takes one k_ex
        oil['coefficients']['external_leakage'] = leak['coefficient']
    return doc


def _status_ok(status: int, values: tuple[float, ...], what: str) -> bool:
    if status == int(PointStatus.OK):
        assert all(math.isfinite(v) for v in values), (what, values)
        return True
    return False


def check_motor(path: Path, what: str) -> str:
    """Load a motor file as the nodes and the CLI do; evaluate a few points; the outcome."""
    try:
        with bounded(what):
            model = MotorOptions(liquid='oil', motor_file=str(path)).build_model()
    except ModelError as err:
        one_line(str(err), what)
        return 'one line'
    channels = dict.fromkeys(model.channels, 1.0)
    flagged = False
    for flow, dp in POINTS:
        point = model.speed_point(flow, dp, channels=channels)
        values = (point.speed, point.flow, *point[4:12])
        flagged |= not _status_ok(int(point.status), values, what)
        if point.status == 0 and flow > 0.0 and dp > 0.0:
            assert point.speed >= 0.0, (what, point)
    return 'flagged' if flagged else 'value'


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    """Run ``satmotor`` in this process, bounded in time; return its code, stdout and stderr."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), \
            bounded(' '.join(map(str, argv))):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def check_operating_point(path: Path, channels: tuple[str, ...] | None, what: str) -> str:
    """
    ``satmotor operating-point`` on a motor file: a point, a flagged one or one line.

    `channels` are given as ``--channel NAME=0.3``; None gives the ones the file's effects
    read (when it loads).
    """
    if channels is None:
        try:
            channels = MotorOptions(liquid='oil', motor_file=str(path)).build_model().channels
        except ModelError:
            channels = ()
    extra = [f'--channel={name}=0.3' for name in channels]
    code, out, err = run_cli(['operating-point', '--motor', path, '--flow', '20', '--dp', '10',
                              '--json', *extra])
    if code != 0:
        assert code == 1, (what, code, err)
        one_line(err, what)
        return 'one line'
    result = json.loads(out)
    if result['status'] == 'OK':
        numbers = [result['speed_rpm'], result['flow_lpm'], *result['losses_lpm'].values()]
        assert None not in numbers, (what, result)
        return 'value'
    return 'flagged'


def check_characteristics(path: Path, out: Path, what: str) -> str:
    """``satmotor characteristics`` on a motor file: the curves (NaN where flagged) or one line."""
    code, stdout, err = run_cli(['characteristics', '--motor', path, '--points', '40',
                                 '--out', out])
    if code != 0:
        assert code == 1 and not out.exists(), (what, code, err)
        one_line(err, what)
        return 'one line'
    assert out.is_dir() and any(out.glob('*.png')), (what, stdout, err)
    return 'value'


HEADER_NAMES = ('time', 'RPM', 'Spd', 'Flow', 'Up', 'Low', 'Case', 'T', 'Pos', 'x y', '')
HEADER_UNITS = ('', '(s)', '(rpm)', '(in/s)', '(l/min)', '(psig)', '(psia)', '[MPa]', '(bar)',
                '(V)', '(degC)', '[', '(()')
CELLS = ('1e308', '-1e308', '1e400', 'nan', 'inf', '', 'x', '1e-320', '9' * 60, '1,5', '"',
         '-0', '0')
UNITS = ('', 'rpm', 'rad/s', 'l/min', 'gpm', 'MPa', 'bar', 'psi', 'psig', 'psia', 'bara', 's',
         'ms', 'degC', 'K', 'in/s', 'N*m', 'V', 'furlong', 1, None)


GOOD_HEADER = ('time(s)', 'RPM', 'Flow(l/min)', 'Up(psig)', 'Low(psig)', 'T(degC)', 'Aux(V)')
GOOD_MAPPING = {'columns': {'time': 'time', 'speed': {'column': 'RPM', 'unit': 'rpm'},
                            'flow': 'Flow', 'p_in': 'Up', 'p_out': 'Low', 'temperature': 'T'},
                'channels': {'aux': {'column': 'Aux', 'optional': True}}}
"""A log and its mapping that read; the generators start from them half of the time."""


def _bench_rows() -> list[list[str]]:
    """Rows of a synthetic bench test of the packaged motor, as GOOD_HEADER spells them."""
    table = generate(Plan(n_points=80), Injection(), seed=5)
    columns = (table.channels['time'], table.speed / RPM, table.flow / LPM,
               table.p_in / PSI, table.p_out / PSI, table.channels['temperature'],
               table.channels['aux'])
    return [[f'{x:.6g}' for x in row] for row in zip(*columns)]


GOOD_ROWS = _bench_rows()


def _good_row(draw: st.DrawFn, i: int) -> list[str]:
    cells = list(GOOD_ROWS[i % len(GOOD_ROWS)])
    if draw(st.integers(0, 150)) == 0:  # an edge cell now and then
        cells[draw(st.integers(0, 6))] = draw(st.sampled_from(CELLS))
    return cells


@st.composite
def logs(draw: st.DrawFn) -> tuple[bytes, list[str]]:
    """Draw a text log (a header in one of three places or none, rows) and its header names."""
    good = draw(st.booleans())
    width = len(GOOD_HEADER) if good else draw(st.integers(1, 7))
    names = list(GOOD_HEADER) if good else [
        draw(st.sampled_from(HEADER_NAMES)) + draw(st.sampled_from(HEADER_UNITS))
        for _ in range(width)]
    sep = draw(st.sampled_from((',', ' ', ';', '\t')))
    rows = []
    for i in range(draw(st.integers(0, 80) if good else st.integers(0, 25))):
        cells = _good_row(draw, i) if good else [
            draw(st.one_of(st.sampled_from(CELLS),
                           st.floats(-1e4, 1e4).map(lambda x: f'{x:.6g}')))
            for _ in range(width + draw(st.sampled_from((0, 0, 0, 0, 1, -1))))]
        rows.append(sep.join(cells))
    if rows and draw(st.integers(0, 7)) == 0:  # a line that is no data row
        rows.insert(draw(st.integers(0, len(rows) - 1)),
                    draw(st.sampled_from(('# note', '', '1 2', '%x'))))
    if good and rows and draw(st.integers(0, 4)) == 0:  # two logs in one file
        rows = rows + rows
    place = 'comment' if good else draw(st.sampled_from(('first', 'comment', 'none')))
    head = [','.join(names)] if place == 'first' else ['#' + ','.join(names)] \
        if place == 'comment' else []
    newline = draw(st.sampled_from(('\n', '\r\n')))
    text = newline.join(head + rows) + newline
    bom = draw(st.sampled_from(('', '\ufeff')))
    return (bom + text).encode('utf-8'), [n.split('(')[0].split('[')[0] for n in names]


@st.composite
def mappings(draw: st.DrawFn, names: list[str]) -> dict:
    """Draw a column mapping for a log with these header names: right, edge or wrong."""
    columns = st.one_of(st.sampled_from(names or ['RPM']), st.integers(-1, 9),
                        st.sampled_from(('nope', '', True, 1.5)))

    def source() -> object:
        if draw(st.booleans()):
            return draw(columns)
        doc = {'column': draw(columns)}
        for key, values in (('unit', st.sampled_from(UNITS)),
                            ('sign', st.sampled_from((1, -1, 0, 'x'))),
                            ('reference', st.sampled_from(('gauge', 'absolute', 'x'))),
                            ('area', st.sampled_from(('1.375 in^2', '0', 'x', '1e300 m^2'))),
                            ('optional', st.sampled_from((True, False, 'yes')))):
            if draw(st.integers(0, 3)) == 0:
                doc[key] = draw(values)
        return doc

    if names == [n.split('(')[0] for n in GOOD_HEADER] and draw(st.integers(0, 3)):
        doc = copy.deepcopy(GOOD_MAPPING)
        for _ in range(draw(st.sampled_from((0, 0, 0, 1, 1, 2)))):  # a few wrong keys
            section = draw(st.sampled_from(('columns', 'channels')))
            doc[section][draw(st.sampled_from(('speed', 'flow', 'p_in', 'aux', 'p_case',
                                               'temperature')))] = source()
        if draw(st.integers(0, 4)) == 0:
            doc['file'] = {'comment': draw(st.sampled_from(('1', '#', '')))}
        return doc
    fields = draw(st.lists(st.sampled_from(FIELDS), min_size=2, max_size=6, unique=True))
    base = ['speed', 'flow'] + (['p_in', 'p_out'] if draw(st.booleans()) else ['p_a', 'p_b'])
    doc = {'columns': {field: source() for field in dict.fromkeys(base + fields)}}
    if draw(st.booleans()):
        doc['channels'] = {draw(st.sampled_from(('aux', 'p_x', 'time', 'c'))) + str(i):
                           source() for i in range(draw(st.integers(0, 3)))}
    if draw(st.booleans()):
        doc['file'] = {'separator': draw(st.sampled_from(('auto', 'comma', 'semicolon', 'tab',
                                                          'whitespace', 'pipe'))),
                       'comment': draw(st.sampled_from(('#', '', '1', '%', 1, None))),
                       'header': draw(st.sampled_from(('auto', 'first', 'comment', 'none',
                                                       'top')))}
    if draw(st.integers(0, 5)) == 0:
        doc[draw(st.sampled_from(('other_columns', 'extra')))] = draw(
            st.sampled_from(('keep', 'drop', 'all')))
    return doc


def check_log(path: Path, doc: dict, what: str) -> str:
    """Read a log through a mapping: an SI table (perhaps with notes) or one line."""
    try:
        with bounded(what):
            table = read_log(path, mapping_from_dict(doc, 'mapping.yaml'))
    except DataError as err:
        one_line(str(err), what)
        return 'one line'
    assert len(table) > 0, what
    for values in (table.speed, table.flow, table.p_in, table.p_out):
        assert np.all(np.isfinite(values)), what
    said = any(note.startswith((IMPOSSIBLE, BAD_CELLS, SANITY)) for note in table.notes)
    return 'flagged' if said else 'value'


def user_dir(path: Path) -> dict[str, bytes]:
    """Make a user's directory at `path`; return its content, to check it is untouched."""
    path.mkdir(parents=True, exist_ok=True)
    (path / 'thesis.tex').write_bytes(b'years of work')
    return snapshot(path)


def snapshot(path: Path) -> dict[str, bytes]:
    """Return every file under `path` and its bytes."""
    return {str(p.relative_to(path)): p.read_bytes() for p in sorted(path.rglob('*'))
            if p.is_file()}


def check_command(command: str, log: Path, mapping: Path, out: Path, what: str) -> str:
    """
    ``calibrate`` or ``validate`` a log through a mapping: a result, flagged or not, or one line.

    A user's directory beside `out` must be left as it was, and `out` must exist only after a
    success.
    """
    mine = out.with_name(out.name + '-mine')
    before = user_dir(mine)
    code, stdout, err = run_cli([command, log, '--columns', mapping, '--liquid', 'oil',
                                 '--out', out])
    assert snapshot(mine) == before, (what, 'the user directory was touched')
    lines = [line for line in err.splitlines() if not line.startswith('warning: ')]
    if code != 0:
        assert code == 1 and not out.exists(), (what, code, err)
        assert len(lines) == 1 and lines[0].startswith('satmotor: error: '), (what, err)
        return 'one line'
    assert not lines and out.is_dir() and stdout.strip(), (what, stdout, err)
    return 'flagged' if 'warning: ' in err or 'WARNING' in stdout else 'value'


__all__ = ['EFFECTS', 'OUTCOMES', 'SECONDS', 'bounded', 'check_characteristics',
           'check_command', 'check_log', 'check_motor', 'check_operating_point', 'effect_blocks',
           'logs', 'mappings', 'motor_doc', 'one_line', 'run_cli', 'snapshot', 'user_dir']

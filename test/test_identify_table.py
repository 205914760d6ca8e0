# SPDX-License-Identifier: Apache-2.0
"""Bench tables: units in the headers, one-line errors, extra columns kept, steady windows."""

import numpy as np
import pytest

from satmotor_ros.identify import DataError, extract_steady, read_csv, steady_points
from satmotor_ros.identify.synthetic import generate_series, Injection, Plan
from satmotor_ros.model.units import LPM, MPA, RPM

HEADER = 'time [s],speed [rpm],flow [l/min],p_in [MPa],p_out [bar],temperature [degC]'


def _write(tmp_path, text, name='t.csv'):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_table_converts_every_listed_unit_to_si(tmp_path):
    text = ('speed [rad/s],flow [m^3/s],p_in [kPa],p_out [Pa],temperature [K],time [s],'
            'p_case [bar],torque [N*m]\n10,1e-4,20000,500000,313.15,1,2,50\n')
    table = read_csv(_write(tmp_path, text))
    assert table.speed[0] == 10.0
    assert table.flow[0] == 1e-4
    assert table.dp[0] == pytest.approx(19.5e6)
    assert table.channels['temperature'][0] == pytest.approx(40.0)
    assert table.channels['p_case'][0] == pytest.approx(2e5)
    assert table.channels['torque'][0] == 50.0


def test_table_reads_hydraulic_units(tmp_path):
    table = read_csv(_write(tmp_path, HEADER + '\n0,600,20,10,5,40\n'))
    assert table.speed[0] == pytest.approx(600 * RPM)
    assert table.flow[0] == pytest.approx(20 * LPM)
    assert table.dp[0] == pytest.approx(9.5 * MPA)


@pytest.mark.parametrize(('text', 'match'), [
    ('speed [rpm],flow [l/min],p_in [MPa]\n1,2,3\n', "missing required column 'p_out'"),
    ('speed [furlong],flow [l/min],p_in [MPa],p_out [MPa]\n1,2,3,4\n',
     "column 'speed \\[furlong\\]': unknown speed unit 'furlong'"),
    ('speed,flow [l/min],p_in [MPa],p_out [MPa]\n1,2,3,4\n', "column 'speed' has no unit"),
    ('speed [rpm],flow [l/min],p_in [MPa],p_out [MPa]\n1,2,x,4\n',
     "column 'p_in' row 2: 'x' is not a number"),
    ('speed [rpm],flow [l/min],p_in [MPa],p_out [MPa],p_tank [inHg]\n1,2,3,4,5\n',
     "column 'p_tank \\[inHg\\]'"),
    ('speed [rpm],flow [l/min],p_a [psi],temperature [K]\n1,2,3,4\n',
     "missing required column 'p_b'"),
    ('speed [rpm],flow [l/min],p_a [psi],p_b [psi],p_in [psi]\n1,2,3,4,5\n',
     'either p_in, p_out or p_a, p_b'),
    ('#time(s),RPM\n 0.0 12\n', "missing required column 'speed'.*--columns"),
    ('0.0,12,1,2\n', 'no header row.*--columns'),
    ('speed [rpm],flow [l/min],p_in [MPa],p_out [MPa],flow [l/min]\n1,2,3,4,5\n',
     "column 'flow' appears 2 times"),
    ('', 'is empty'),
    ('speed [rpm] x,flow [l/min],p_in [MPa],p_out [MPa]\n1,2,3,4\n',
     'column 1 header .*expected "name \\[unit\\]"'),
    ('[rpm],flow [l/min],p_in [MPa],p_out [MPa]\n1,2,3,4\n', 'column 1 header'),
])
def test_table_errors_are_one_line_naming_the_column(tmp_path, text, match):
    with pytest.raises(DataError, match=match) as info:
        read_csv(_write(tmp_path, text))
    assert '\n' not in str(info.value)


def test_table_takes_units_in_parentheses_as_a_log_does(tmp_path):
    """One header rule for tables and logs: ``flow (l/min)`` is ``flow [l/min]``."""
    text = 'speed (rpm),flow (l/min),p_in (MPa),p_out [MPa]\n600,20,10,0.5\n'
    table = read_csv(_write(tmp_path, text))
    assert table.units['flow'] == 'l/min' and table.flow[0] == pytest.approx(20 / 60000)


def test_table_keeps_extra_columns_even_with_units_it_does_not_know(tmp_path):
    text = HEADER + ',vibration [mm/s],humidity [%]\n0,600,20,10,5,40,1.5,60\n'
    table = read_csv(_write(tmp_path, text))
    assert table.channels['vibration'][0] == 1.5
    assert table.channels['humidity'][0] == 60.0
    assert table.units['humidity'] == '%'


def test_table_drops_rows_missing_a_required_value_and_says_so(tmp_path):
    text = HEADER + '\n0,600,20,10,5,40\n1,,20,10,5,40\n'
    table = read_csv(_write(tmp_path, text))
    assert len(table) == 1
    assert 'dropped 1 rows' in table.notes[0]


def test_steady_windows_recover_the_set_points_and_keep_every_channel():
    plan = Plan(liquid='oil', extra_channels=('aux', 'valve'))
    raw = generate_series(plan, Injection(), seed=2, samples=6000, rate=100.0, hold_s=6.0)
    points = extract_steady(raw)
    # 60 s of 6 s holds: one window per hold, less the first transient at most
    assert 8 <= len(points) <= 11
    assert {'aux', 'valve', 'temperature', 'p_case', 'time', 'revolutions'} <= set(
        points.channels)
    # averaged over a steady window, speed is within the noise of a set-point
    held = raw.speed[(raw.channels['time'] > 3.0) & (raw.channels['time'] < 5.9)]
    first = points.speed[0]
    assert abs(first - np.mean(held)) < 3 * RPM
    assert np.all(np.diff(points.channels['time']) > 0)


def test_steady_points_auto_mode_tells_series_from_points():
    plan = Plan(liquid='water')
    raw = generate_series(plan, Injection(), seed=1, samples=3000, rate=50.0, hold_s=5.0)
    assert len(steady_points(raw.__class__(**{**raw.__dict__, 'time_series': False}))) < 20
    from satmotor_ros.identify.synthetic import generate
    table = generate(plan, Injection(), seed=1)
    assert len(steady_points(table)) == len(table)


def test_steady_extraction_without_steady_window_is_a_clear_error():
    plan = Plan(liquid='oil')
    raw = generate_series(plan, Injection(), seed=1, samples=400, rate=100.0, hold_s=0.3)
    with pytest.raises(DataError, match='no steady window'):
        extract_steady(raw)


def test_table_accepts_semicolons_decimal_commas_and_unit_case(tmp_path):
    text = 'Speed [RPM];Flow [L/min];p_in [MPa];p_out [mbar]\n600;20,5;10;5000\n'
    table = read_csv(_write(tmp_path, text))
    assert table.speed[0] == pytest.approx(600 * RPM)
    assert table.flow[0] == pytest.approx(20.5 * LPM)
    assert table.p_out[0] == pytest.approx(5e5)


def test_table_reads_port_pressures_with_signed_speed_and_flow(tmp_path):
    text = ('time [s],speed [rpm],flow [l/min],p_a [psi],p_b [psig]\n'
            '0,600,20,1000,50\n1,-600,-20,50,1000\n')
    table = read_csv(_write(tmp_path, text))
    psi = 6894.757293168
    assert table.p_in == pytest.approx([1000 * psi, 50 * psi])  # p_in is port A
    assert table.p_out == pytest.approx([50 * psi, 1000 * psi])
    assert table.speed[1] == pytest.approx(-600 * RPM)
    assert table.flow[1] == pytest.approx(-20 * LPM)
    assert 'p_a' not in table.channels and table.units['p_in'] == 'psi'


def test_table_makes_absolute_pressures_gauge(tmp_path):
    text = 'speed [rpm],flow [l/min],p_in [bara],p_out [psia]\n600,20,11.01325,14.6959\n'
    table = read_csv(_write(tmp_path, text))
    assert table.p_in[0] == pytest.approx(1.0e6)
    assert table.p_out[0] == pytest.approx(0.0, abs=10.0)


def test_table_drops_rows_below_vacuum_and_names_the_column(tmp_path):
    rows = ''.join(f'{600 + i},20,{p},0\n' for i, p in enumerate([100, -15.5, 90, 80, 70]))
    table = read_csv(_write(tmp_path, 'speed [rpm],flow [l/min],p_a [psig],p_b [psig]\n' + rows))
    assert len(table) == 4
    assert table.speed[1] == pytest.approx(602 * RPM)
    note = [n for n in table.notes if n.startswith('impossible values')]
    assert len(note) == 1
    assert "column 'p_a'" in note[0] and 'dropped 1 rows' in note[0] and '-106.9 kPa' in note[0]


def test_table_refuses_a_file_whose_pressures_are_mostly_impossible(tmp_path):
    rows = ''.join(f'600,20,{p},0\n' for p in [-2, -3, -4, 5])  # absolute MPa read as bar?
    with pytest.raises(DataError, match="column 'p_in': 3 of 4 values are a gauge pressure "
                                        'below vacuum.*gauge or absolute'):
        read_csv(_write(tmp_path, 'speed [rpm],flow [l/min],p_in [bar],p_out [bar]\n' + rows))


def test_table_refuses_a_temperature_below_absolute_zero_in_most_rows(tmp_path):
    text = 'speed [rpm],flow [l/min],p_in [MPa],p_out [MPa],temperature [K]\n600,20,10,1,-5\n'
    with pytest.raises(DataError, match="column 'temperature'.*below absolute zero"):
        read_csv(_write(tmp_path, text))


def test_table_reads_blank_separated_rows_under_a_commented_header(tmp_path):
    text = ('# a log\n#speed [rpm],flow [l/min],p_in [MPa],p_out [MPa]\n'
            '  600  20 10 1\n 700 21 11 1\n')
    table = read_csv(_write(tmp_path, text))
    assert len(table) == 2 and table.speed[1] == pytest.approx(700 * RPM)


def test_written_epoch_times_keep_their_sub_second_steps(tmp_path):
    """A time column of epoch seconds at 100 Hz reads back to the hundredth of a second."""
    from satmotor_ros.identify import write_csv
    time = 1.78e9 + np.arange(50) / 100.0
    path = tmp_path / 'epoch.csv'
    write_csv(path, {'time': ('s', time), 'speed': ('rad/s', np.full(50, 10.0)),
                     'flow': ('m^3/s', np.full(50, 1e-4)), 'p_in': ('Pa', np.full(50, 1e7)),
                     'p_out': ('Pa', np.full(50, 5e5))})
    assert read_csv(path).channels['time'] == pytest.approx(time, abs=1e-6, rel=0.0)

# SPDX-License-Identifier: Apache-2.0
"""
rosbag2 recordings of the DESIGN.md topics as a bench time series.

Reads through :mod:`satmotor_ros.bags` (no second bag reader). Topics map to
the bench-table columns: ``flow_measured`` (or, without a flowmeter,
``flow_command``) -> flow, ``inlet_pressure`` -> p_in, ``outlet_pressure``
-> p_out, ``joint_states`` velocity of the shaft joint -> speed;
``case_pressure`` -> p_case, ``fluid_temperature`` -> temperature,
``load_torque`` -> torque; any other Float64, FluidPressure or Temperature
topic is kept as a channel named after the topic's last name element. The
model's own outputs (``predicted_joint_state``, ``speed_residual``,
``losses/*``) are not measurements and are left out. Every topic is
interpolated onto the sample times of ``joint_states``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
from satmotor_ros.bags import (BagError, describe_topics, FIELDS, list_topics, read_series,
                               Series)
from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.table import BenchTable, table_from_columns
from satmotor_ros.interface import CHANNELS, JOINT_NAME, MODEL_OUTPUTS
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.units import gauge


COLUMNS = {CHANNELS[c].topic: (c, CHANNELS[c].field)
           for c in ('p_in', 'p_out', 'p_case', 'temperature', 'torque')}
"""DESIGN.md topic -> (bench column, message field)."""

_FLOWS = (CHANNELS['flow_measured'].topic, CHANNELS['flow'].topic)  # flowmeter first
_SHAFT = CHANNELS['measured_speed']

REQUIRED_TOPICS = tuple(CHANNELS[c].topic for c in ('p_in', 'p_out', 'measured_speed'))
"""Topics a calibration bag must have, besides flow_measured or flow_command."""


def _on(series: Series, field: str, t: FloatArray, t0: int) -> FloatArray:
    """Interpolate one field onto the times `t` [s]; NaN beyond one period outside its span."""
    ts = (series.t_ns - t0) * 1.0e-9
    values = series.fields[field]
    ok = np.isfinite(values)
    if ok.sum() < 2:
        return np.full(t.shape, float(values[ok][0]) if ok.any() else np.nan)
    ts, values = ts[ok], values[ok]
    out = np.interp(t, ts, values)
    period = float(np.median(np.diff(ts)))
    out[(t < ts[0] - period) | (t > ts[-1] + period)] = np.nan
    return out


def _extra_topics(path: Path) -> dict[str, str]:
    infos = list_topics(path)
    out = {}
    known = set(COLUMNS) | {*_FLOWS, _SHAFT.topic}
    for name, info in infos.items():
        base = name.rstrip('/').rsplit('/', 1)[-1]
        if (base in known or info.msgtype not in FIELDS or info.count == 0
                or any(m in name for m in MODEL_OUTPUTS)):
            continue
        if info.msgtype.endswith('JointState'):
            continue
        out[name] = base
    return out


def read_bag(path: str | Path, joint: str | None = JOINT_NAME,
             topic_map: Mapping[str, str] | None = None) -> BenchTable:
    """
    Read a calibration recording into a time-series :class:`BenchTable`.

    Parameters
    ----------
    path : str or pathlib.Path
        rosbag2 directory (sqlite3 or MCAP) or storage file, [-]
    joint : str or None
        Joint of the motor shaft in ``joint_states``, [-]
    topic_map : mapping, optional
        Bag topic -> DESIGN.md name, for bags recorded under other names, [-]

    Returns
    -------
    BenchTable
        Samples at the ``joint_states`` times, pressures gauge, ``time_series`` True.

    Raises
    ------
    DataError
        One line: the storage or metadata problem, or the required topics missing.

    """
    path = Path(path)
    wanted = [*_FLOWS, _SHAFT.topic, *COLUMNS]
    try:
        series = read_series(path, wanted, topic_map, joint)
    except BagError as err:
        msg = f'bag {str(path)!r}: {err}'
        raise DataError(msg) from None
    flow_topic = next((n for n in _FLOWS
                       if n in series and len(series[n])), None)
    missing = [n for n in REQUIRED_TOPICS if n not in series or not len(series[n])]
    if flow_topic is None:
        missing.insert(0, 'flow_measured (or flow_command)')
    if missing or flow_topic is None:
        try:
            has = describe_topics(list_topics(path), limit=5)
        except BagError:
            has = 'unreadable topic list'
        msg = (f'bag {str(path)!r} lacks the calibration topic(s) {", ".join(missing)} '
               f'(has: {has})')
        raise DataError(msg)
    try:
        extra = {} if topic_map else _extra_topics(path)
        extra_series = read_series(path, list(extra)) if extra else {}
    except BagError as err:
        msg = f'bag {str(path)!r}: {err}'
        raise DataError(msg) from None
    shaft = series[_SHAFT.topic]
    t0 = int(shaft.t_ns[0])
    t = (shaft.t_ns - t0).astype(np.float64) * 1.0e-9
    columns: dict[str, tuple[str, np.ndarray]] = {
        'time': ('s', t), 'speed': ('rad/s', shaft.fields[_SHAFT.field]),
        'flow': ('m^3/s', _on(series[flow_topic], 'data', t, t0))}
    for topic, (column, field) in COLUMNS.items():
        if topic in series and len(series[topic]):
            unit = 'degC' if column == 'temperature' else 'N*m' if column == 'torque' else 'Pa'
            columns[column] = (unit, _on(series[topic], field, t, t0))
    for column in ('p_in', 'p_out', 'p_case'):  # FluidPressure is absolute
        if column in columns:
            columns[column] = ('Pa', gauge(columns[column][1]))
    for name, base in extra.items():
        s = extra_series.get(name)
        if s is not None and len(s) and base not in columns:
            field = FIELDS[s.msgtype][0]
            columns[base] = ('', _on(s, field, t, t0))
    table = table_from_columns(columns, str(path), time_series=True)
    notes = (f'rosbag2: flow from {flow_topic}, speed from joint_states, {len(t)} samples on '
             'its times; pressures made gauge (- 101325 Pa)',)
    return BenchTable(table.speed, table.flow, table.p_in, table.p_out, table.channels,
                      table.units, table.source, True, notes + table.notes)

# SPDX-License-Identifier: Apache-2.0
"""
The demo's health section: the motor monitor over the demo's bags, one run after the other.

The monitor (:mod:`satmotor_ros.identify.health`, the estimator of ``satmotor monitor`` and
the ``motor_monitor`` node) watches the model-based run, then the closing-the-loop run,
against the packaged motor the plant runs. The demo's runs last seconds, not hours, so the
monitor's time scales are the demo's: it learns on most of the first run and pools the
samples into bins of :data:`BIN_S`; the false-alarm interval stays the default. Its outputs
go to ``health/`` (monitor.json, health.csv, report.md, plots), as ``satmotor monitor``
writes them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from satmotor_ros.identify.bag import read_bag
from satmotor_ros.identify.health import Baseline, HealthSettings
from satmotor_ros.identify.health.report import write_monitor
from satmotor_ros.identify.health.run import monitor_recordings
from satmotor_ros.model import MotorModel

HEALTH_DIR = 'health'
"""Where the monitor's outputs go, inside the demo's output directory."""

BIN_S = 1.0
"""The monitor's bin at the demo's scale (10 s for hours of data), [s]."""

LEARN_SHARE = 0.8
"""Share of the first run the monitor learns the noise and the level on, [-]."""


def demo_settings(first_s: float) -> HealthSettings:
    """
    Scale the monitor to runs of seconds: learn on the first run, bins of :data:`BIN_S`.

    Parameters
    ----------
    first_s : float
        Length of the first run, [s]

    Returns
    -------
    HealthSettings
        Windows of a few bins; the default false-alarm interval and limits.

    """
    return HealthSettings(learn_hours=LEARN_SHARE * first_s / 3600.0, bin_s=BIN_S,
                          window_s=5.0 * BIN_S, trend_point_s=5.0 * BIN_S,
                          explain_s=max(first_s, 30.0 * BIN_S))


def _value(x: Any, digits: str = '.3g') -> str:
    return 'n/a' if x is None else format(x, digits)


def health_section(out: Path, liquid: str, bags: list[Path],
                   injected: dict[str, Any]) -> list[str]:
    """
    Run the monitor over the bags and return the report's section.

    Parameters
    ----------
    out : pathlib.Path
        The demo's output directory (``health/`` is made in it), [-]
    liquid : str
        The runs' liquid, [-]
    bags : list of pathlib.Path
        The runs' bags in the order they ran: a healthy one first, [-]
    injected : dict
        What the plant had injected in the last run (``effects.*``), for the text, [-]

    Returns
    -------
    list of str
        Markdown lines.

    """
    tables = [read_bag(bag) for bag in bags]
    first_s = float(tables[0].channels['time'][-1] - tables[0].channels['time'][0])
    settings = demo_settings(first_s)
    model = MotorModel.default(liquid)
    run = monitor_recordings(tables, Baseline(model, source=f'{model.name} ({liquid})'),
                             settings)
    (out / HEALTH_DIR).mkdir()
    doc = write_monitor(run, out / HEALTH_DIR)
    effects = ', '.join(f'`{k.removeprefix("effects.")} = {v:g}`' for k, v in injected.items()
                        if k.startswith('effects.')) or 'none'
    lines = ['', '## Health over the runs', '',
             f'The motor monitor (`satmotor monitor`, the `motor_monitor` node) watched the runs '
             f'one after the other ({", ".join(f"`{b.name}`" for b in bags)}) against the '
             f'packaged motor the plant runs, {model.name} on {liquid}. The runs last seconds, '
             f"so its time scales are the demo's: it learned the noise and the level on the "
             f'first {settings.learn_hours * 3600.0:.0f} s of the first run, in bins of '
             f'{settings.bin_s:g} s (hours of data take 10 s bins and 15 min of learning); the '
             f'false-alarm interval is the default {settings.false_alarm_hours:g} h. The last '
             f'run had injected: {effects}.', '',
             '| alarm at [s] | kind | what | change from [s] | leakage factor before | after |',
             '| ---: | --- | --- | ---: | ---: | ---: |']
    for alarm in doc['alarms']:
        lines.append(f'| {_value(alarm["time_s"], ".1f")} | {alarm["kind"]} | '
                     f'{alarm["what"]} | {_value(alarm.get("change_s"), ".1f")} | '
                     f'{_value(alarm.get("before"))} | {_value(alarm.get("after"))} |')
    if not doc['alarms']:
        lines.append('| none | | | | | |')
    spans = ', '.join(f'`{Path(r["data"]).name}` {_value(r["start_s"], ".0f")}-'
                      f'{_value(r["end_s"], ".0f")} s' for r in doc['recordings'])
    now = doc['leakage_factor_now']
    lines += ['', f"On the monitor's clock: {spans}. Leakage factor at the end "
              f'{_value(now["value"])} (95 % '
              f'[{_value(now["ci95"][0])}, {_value(now["ci95"][1])}]), over '
              f'{doc["n_samples"]} samples ({doc["n_skipped"]} skipped: '
              f'{", ".join(f"{k} {v}" for k, v in doc["skipped"].items() if v) or "none"}). '
              f'Details, the time series and the plots: [{HEALTH_DIR}/report.md]'
              f'({HEALTH_DIR}/report.md).', '',
              f'![leakage factor]({HEALTH_DIR}/leakage_factor.png)']
    return lines


__all__ = ['BIN_S', 'HEALTH_DIR', 'demo_settings', 'health_section']

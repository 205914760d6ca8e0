# SPDX-License-Identifier: Apache-2.0
"""
What changed at a fleet's change alarm: the health monitor's explainer on the two recordings.

A change alarm sits between two consecutive recordings of a motor (the health monitor's own,
raised in a recording, between it and the point before it). The calibration loop's
candidates run on the recording before it and on the one after, against the motor's
baseline (:func:`~satmotor_ros.identify.health.explain.explain_change`, as ``satmotor
monitor`` names a change), and the effect the second asks for and the first does not is
what changed. The answer is kept beside the second recording's outputs
(:data:`CHANGE`), keyed by both recordings' content and the baseline, so a rerun reads it.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from satmotor_ros.fleet.discover import Motor
from satmotor_ros.fleet.resume import options_key
from satmotor_ros.fleet.tasks import columns_of, load_screened, motor_options, Refused, RunOptions

CHANGE = '.fleet-change.json'
"""The explanation of the change alarm at a recording, in its output directory."""


def explain_alarms(view: dict[str, Any], motor: Motor, baseline: dict[str, Any] | None,
                   markers: dict[str, dict[str, Any]], run: RunOptions) -> None:
    """
    Add what changed to each change alarm of a motor's view, the monitor's too (in place).

    Parameters
    ----------
    view : dict
        The motor's fleet.json entry (:func:`~satmotor_ros.fleet.summary.motor_view`), [-]
    motor : Motor
        The motor and its recordings, [-]
    baseline : dict or None
        Its baseline, [-]
    markers : dict
        Recording -> its done-marker, [-]
    run : RunOptions
        The run's options, [-]

    """
    if not baseline or not baseline.get('coefficients'):
        return
    series = [p['recording'] for p in view['leakage_factor']]
    records = {r.relative: r for r in motor.recordings}
    for alarm in view['alarms']:
        after = alarm.get('recording')
        before = _before(after, series, motor, markers)
        if alarm['kind'] != 'change' or after not in records or before is None:
            continue
        key = options_key({'before': markers.get(before, {}).get('content'),
                           'after': markers.get(after, {}).get('content'),
                           'baseline': baseline.get('key')})
        place = Path(run.out) / motor.motor / records[after].name / CHANGE
        found = _cached(place, key)
        if found is None:
            found = _explain(records[before], records[after], motor, baseline, run)
            _keep(place, {'key': key, 'what': found, 'before': before})
        alarm['what'] += f'; what changed: {found}'


def _before(after: str | None, series: list[str], motor: Motor,
            markers: dict[str, dict[str, Any]]) -> str | None:
    """
    Return the recording an alarm's is compared with: the point before it, else the done one.

    A change alarm of the ratios is between two points; the monitor's is raised in its
    recording, whose point may be the first (the recordings before it refused, or learned on).
    """
    if after in series and series.index(after) > 0:
        return series[series.index(after) - 1]
    names = [r.relative for r in motor.recordings]
    if after not in names:
        return None
    done = [n for n in names[:names.index(after)]
            if markers.get(n, {}).get('status') == 'done']
    return done[-1] if done else None


def _cached(place: Path, key: str) -> str | None:
    try:
        kept = json.loads(place.read_text(encoding='utf-8'))
    except (OSError, ValueError):
        return None
    return str(kept['what']) if isinstance(kept, dict) and kept.get('key') == key else None


def _keep(place: Path, content: dict[str, Any]) -> None:
    place.parent.mkdir(parents=True, exist_ok=True)
    temporary = place.with_name(f'{place.name}.partial-{os.getpid()}')
    temporary.write_text(json.dumps(content) + '\n', encoding='utf-8')
    os.replace(temporary, place)


def _explain(before: Any, after: Any, motor: Motor, baseline: dict[str, Any],
             run: RunOptions) -> str:
    """Run the explainer on the two recordings; 'unexplained (...)' where it cannot."""
    from satmotor_ros.identify import IdentificationError
    from satmotor_ros.identify.health import Baseline, HealthSamples
    from satmotor_ros.identify.health.explain import explain_change
    from satmotor_ros.model import ModelError
    columns = columns_of(motor.rule, run)
    try:
        sides = [HealthSamples.from_table(load_screened(rec, motor_options(motor.rule, run),
                                                        columns)[0])
                 for rec in (before, after)]
        healthy = Baseline.load(baseline['coefficients'], baseline['liquid'])
        return explain_change(sides[0], sides[1], healthy)
    except (Refused, IdentificationError, ModelError, OSError) as err:
        text = str(err).strip().splitlines()
        return 'unexplained (' + (text[0] if text else type(err).__name__) + ')'


__all__ = ['CHANGE', 'explain_alarms']

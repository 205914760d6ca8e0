# SPDX-License-Identifier: Apache-2.0
"""
The demo closes the loop: calibrate the bag of a run whose plant has an effect the model lacks.

The run is recorded like the others; the calibration reads its bag as ``satmotor calibrate``
would, writes its own outputs under ``loop/`` and returns a section of ``report.md``: what
was injected, the effects found one after the other, the error before and after, and a
verdict that claims no more than the data show (:func:`verdict`).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from satmotor_ros.identify import calibrate, IdentificationError
from satmotor_ros.identify.bag import read_bag
from satmotor_ros.identify.output import write_json, write_yaml
from satmotor_ros.identify.pipeline import Calibration
from satmotor_ros.identify.report import UNSEPARABLE, write_report
from satmotor_ros.model.units import MPA, RPM
from satmotor_ros.plant.scenario import Cycle

LOOP_DIR = 'loop'
"""Where the calibration of the loop run goes, inside the demo's output directory."""


def _injected(effects: dict[str, Any]) -> str:
    return ', '.join(f'`{k.removeprefix("effects.")} = {v:g}`' for k, v in effects.items()
                     if k.startswith('effects.'))


def _sensors(effects: dict[str, Any]) -> str:
    return ', '.join(f'{k.split(".")[1]} {v:.3g}' for k, v in effects.items()
                     if k.startswith('sensors.') and k.endswith('.noise'))


def _hold(cycle: Cycle) -> str:
    holds = {round(seg.duration, 6) for seg in cycle.segments}
    return f'{holds.pop():.3g} s' if len(holds) == 1 else f'{min(holds):.3g}-{max(holds):.3g} s'


def _case(cycle: Cycle) -> str:
    offsets = sorted({seg.case_offset for seg in cycle.segments if seg.case_offset is not None})
    if len(offsets) < 2:
        return ''
    return (f', the case drain throttled to {len(offsets)} case pressures '
            f'({", ".join(f"{p / MPA:g}" for p in offsets)} MPa above tank, a Latin square over '
            'speed and load: a leak to the case then differs from the losses that follow the '
            'speed)')


def separation(cal: Calibration, label: str) -> tuple[str, float]:
    """
    Give the base parameter the found effect correlates with most, and r.

    Parameters
    ----------
    cal : Calibration
        The result, [-]
    label : str
        The effect's name among the final fit's parameters, [-]

    Returns
    -------
    tuple of (str, float)
        The base parameter (a factor of a loss component) and the correlation, [-];
        ``('', nan)`` when the effect or the base parameters are not in the fit.

    """
    names = list(cal.final.names)
    base = [i for i, n in enumerate(names) if n in {c.name for c in cal.parts.components}]
    if label not in names or not base:
        return '', float('nan')
    row = np.asarray(cal.final.correlation)[names.index(label)]
    worst = max(base, key=lambda i: abs(row[i]))
    return names[worst], float(row[worst])


def verdict(injected: dict[str, float], summary: dict[str, Any], cal: Calibration) -> list[str]:
    """
    Judge what the calibration found against what was injected, claiming no more than shown.

    The injected effect is *named* only when it is among the effects found AND its
    interval covers the injected value; a name with an interval that misses the value,
    an effect the data cannot separate from a base parameter (|r| > UNSEPARABLE) and a
    transient term with a value that cannot be (negative) are each said.

    Parameters
    ----------
    injected : dict
        Effect name -> injected value (SI), [-]
    summary : dict
        calibration.json's object, [-]
    cal : Calibration
        The result (for the correlations), [-]

    Returns
    -------
    list of str
        Sentences for the report.

    """
    found = {e['effect']: e for e in summary['effects']}
    # the effect's parameter in the final fit: a fitted form's by its id and side
    labels = {s.effect: s.effect if s.added.shape else s.label for s in cal.found}
    out = []
    for name, value in injected.items():
        e = found.get(name)
        if e is None:
            out.append(f'It did not name the injected `{name}`: see the report for what it '
                       'found instead.')
            continue
        lo, hi = e['ci95']
        covered = lo <= value <= hi
        other, r = separation(cal, labels.get(name, name))
        apart = not abs(r) > UNSEPARABLE  # NaN: nothing to be confused with
        if covered and apart:
            out.append(f'It named the injected `{name}`: its interval [{lo:.4g}, {hi:.4g}] '
                       f'covers the injected {value:g}.')
        elif covered:
            out.append(f'It found `{name}` with an interval that covers the injected {value:g}, '
                       'but it cannot tell it apart from a base parameter (below): not named.')
        else:
            out.append(f'It found `{name}`, but its interval [{lo:.4g}, {hi:.4g}] does not '
                       f'cover the injected {value:g}: not named (the value is off).')
        if other:
            out.append(f'Its strongest correlation with a base parameter is with `{other}`: '
                       f'r = {r:+.3f} (' + ('separated' if apart else
                                            f'|r| > {UNSEPARABLE}: not separable, only their '
                                            'combination is determined') + ').')
    impossible = [d['term'] for d in summary.get('dynamics', []) if 'impossible' in d]
    if impossible:
        out.append(f'The transient term(s) {", ".join(f"`{t}`" for t in impossible)} came out '
                   'negative, which cannot be: they are no estimates (they absorb what the '
                   'model lacks).')
    return out


def close_loop(bag: Path, liquid: str, effects: dict[str, Any], out: Path,
               cycle: Cycle) -> list[str]:
    """
    Calibrate the loop run's bag into ``out/loop`` and describe it for report.md.

    Parameters
    ----------
    bag : pathlib.Path
        The recorded run, [-]
    liquid : str
        Its coefficient set, [-]
    effects : dict
        ``effects.<name>`` -> value injected into its plant (SI), [-]
    out : pathlib.Path
        The demo's output directory, [-]
    cycle : Cycle
        The loop run's cycle (its holds and case pressures), [-]

    Returns
    -------
    list of str
        The lines of the report's section.

    """
    speeds = sorted({seg.setpoint for seg in cycle.segments})
    loads = sorted({seg.load for seg in cycle.segments})
    lines = ['## Closing the loop', '',
             f'One more run, {liquid} with the model feed-forward on an identification '
             f'cycle ({len(cycle.segments)} speed and load points held {_hold(cycle)} each, '
             f'{speeds[0] / RPM:.0f}-{speeds[-1] / RPM:.0f} rpm by {loads[0]:g}-{loads[-1]:g} '
             f'N*m{_case(cycle)}, the way a bench calibrates), had a plant with '
             f'{_injected(effects)}: an effect the motor model does not know (it is in the '
             'virtual motor only), and sensors with the white noise of a bench (standard '
             f'deviations, SI: {_sensors(effects)}). `satmotor calibrate` then read the bag '
             f'of that run (`{bag.relative_to(out)}`) as any recording, without being told '
             'what was injected.', '']
    try:
        # named as it will be once the demo's output is in place, not by its temporary path
        cal = calibrate(replace(read_bag(bag), source=f'bags/{bag.name}'), liquid)
    except IdentificationError as err:
        return lines + [f'The calibration refused the recording: {err}', '']
    target = out / LOOP_DIR
    target.mkdir()
    summary = write_json(cal, target / 'calibration.json')
    write_yaml(cal, target / 'coefficients.yaml')
    write_report(cal, target, summary)
    before, after = summary['error_before'], summary['error_after']
    rows = [f'| `{e["effect"]}` | {e["coefficient"]:.4g} {e["unit"]} | '
            f'[{e["ci95"][0]:.4g}, {e["ci95"][1]:.4g}] | {e["error_after"]["rmse_lpm"]:.4g} |'
            for e in summary['effects']]
    injected = {k.removeprefix('effects.'): float(v) for k, v in effects.items()
                if k.startswith('effects.') and isinstance(v, (int, float))}
    cut = 100.0 * (1.0 - after['rmse_lpm'] / before['rmse_lpm']) if before['rmse_lpm'] else 0.0
    lines += [f'Found, one after the other, from {summary["n_points"]} points:', '',
              '| effect | coefficient | ci95 | CV error after [l/min] |',
              '| --- | ---: | ---: | ---: |', *(rows or ['| none | | | |']), '',
              f'Out-of-sample error of Q_vl: {before["rmse_lpm"]:.4g} l/min before, '
              f'{after["rmse_lpm"]:.4g} l/min after ({cut:.0f} % less).', '',
              *verdict(injected, summary, cal), '',
              f'The full calibration: [{LOOP_DIR}/report.md]({LOOP_DIR}/report.md), with '
              '`calibration.json` and `coefficients.yaml` (loadable by the nodes) beside it.', '',
              f'![residuals]({LOOP_DIR}/residuals.png)', '']
    return lines


__all__ = ['LOOP_DIR', 'close_loop', 'separation', 'verdict']

# SPDX-License-Identifier: Apache-2.0
"""
The demo closes the loop: calibrate the bag of a run whose plant has an effect the model lacks.

The run is recorded like the others; the calibration reads its bag as ``satmotor calibrate``
would, writes its own outputs under ``loop/`` and returns a section of ``report.md``: what
was injected, the effects found one after the other, the error before and after.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

from satmotor_ros.identify import calibrate, IdentificationError
from satmotor_ros.identify.bag import read_bag
from satmotor_ros.identify.output import write_json, write_yaml
from satmotor_ros.identify.report import write_report

LOOP_DIR = 'loop'
"""Where the calibration of the loop run goes, inside the demo's output directory."""


def _injected(effects: dict[str, Any]) -> str:
    return ', '.join(f'`{k.removeprefix("effects.")} = {v:g}`' for k, v in effects.items()
                     if k.startswith('effects.'))


def _sensors(effects: dict[str, Any]) -> str:
    return ', '.join(f'{k.split(".")[1]} {v:.3g}' for k, v in effects.items()
                     if k.startswith('sensors.') and k.endswith('.noise'))


def close_loop(bag: Path, liquid: str, effects: dict[str, Any], out: Path) -> list[str]:
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

    Returns
    -------
    list of str
        The lines of the report's section.

    """
    lines = ['## Closing the loop', '',
             f'One more run, {liquid} with the model feed-forward on an identification '
             'cycle (nine speed and load points held 4 s each, 300-1200 rpm by 20-80 N*m, '
             'the way a bench calibrates), had a plant with '
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
    injected = {k.removeprefix('effects.') for k in effects if k.startswith('effects.')}
    found = {e['effect'] for e in summary['effects']}
    verdict = ('It named the injected effect.' if injected & found else
               'It did not name the injected effect: see the report for what it found instead.')
    lines += [f'Found, one after the other, from {summary["n_points"]} points:', '',
              '| effect | coefficient | ci95 | CV error after [l/min] |',
              '| --- | ---: | ---: | ---: |', *(rows or ['| none | | | |']), '',
              f'Out-of-sample error of Q_vl: {before["rmse_lpm"]:.4g} l/min before, '
              f'{after["rmse_lpm"]:.4g} l/min after. {verdict} The full calibration: '
              f'[{LOOP_DIR}/report.md]({LOOP_DIR}/report.md), with `calibration.json` and '
              f'`coefficients.yaml` (loadable by the nodes) beside it.', '',
              f'![residuals]({LOOP_DIR}/residuals.png)', '']
    return lines


__all__ = ['LOOP_DIR', 'close_loop']

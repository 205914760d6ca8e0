# SPDX-License-Identifier: Apache-2.0
"""
Identification and false-positive rates over seeds and magnitudes.

``.venv/bin/python bench/bench_sweep_rates.py --seeds 20`` generates a bench table
per liquid, effect, magnitude and seed (``identify/synthetic.py``), calibrates it,
and prints one row per case: how often the injected effect was named
(``correct``; ``or tie`` also counts a near-tie runner-up, as for the two
sensor gains that no bench can tell apart; a fitted form counts by its kind,
its exponents fitted), how often ``none`` was said,
the median cut of the out-of-sample error, and how often the cut is >= 3x
or the error after is within 1.5x the noise of Q_vl (steady tables only;
for time series the cut alone). For ``none`` the rate of any effect named
is the false-positive rate.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
import sys
import time

import numpy as np

from satmotor_ros.identify.pipeline import calibrate
from satmotor_ros.identify.synthetic import (generate, generate_series, Injection, Plan,
                                             REALISTIC)

Case = tuple[str, str, float, int, bool]


def run_case(case: Case) -> tuple[str, str, str, float, float, float]:
    """
    Generate and calibrate one case.

    Parameters
    ----------
    case : tuple
        (liquid, effect, scale on the realistic magnitude, seed, time series), [-]

    Returns
    -------
    tuple
        (chosen effect, runner-up effect or '', injected effect, error before,
        error after, noise of Q_vl) with errors and noise in l/min.

    """
    liquid, effect, scale, seed, series = case
    plan = Plan(liquid=liquid)
    injection = Injection.realistic(effect, scale, liquid)
    if series:
        table = generate_series(plan, injection, seed, samples=30000)
    else:
        table = generate(plan, injection, seed)
    cal = calibrate(table, liquid)
    chosen = cal.chosen.effect if cal.chosen else 'none'
    runner = cal.selection.runner_up
    # a steady point's noise; a time series' windows average many samples (not counted)
    noise = float('nan') if series else float(
        np.sqrt(np.mean(plan.noise_lpm(table.flow, cal.model) ** 2)))
    return (chosen, runner.effect if runner else '', effect,
            cal.error_before.rmse_lpm, cal.error_after.rmse_lpm, noise)


def names(found: str, effect: str) -> bool:
    """Return whether `found` names `effect` (a fitted form by its kind: its exponents vary)."""
    kind = effect.partition(':')[0]
    return found == effect or (kind in ('term', 'threshold') and found.startswith(f'{kind}:'))


def _percent(rates: list[float]) -> str:
    return f'{100 * np.mean(rates):.1f} %' if rates else 'n/a'


def main(argv: Sequence[str] | None = None) -> int:
    """
    Run the sweep and print the table.

    Parameters
    ----------
    argv : sequence of str, optional
        Options such as ``--seeds 20``; the process's own when omitted, [-]

    Returns
    -------
    int
        0, once the table is printed.

    """
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seeds', type=int, default=20)
    parser.add_argument('--scales', type=float, nargs='+', default=[0.5, 1.0, 2.0])
    parser.add_argument('--liquids', nargs='+', default=['oil', 'water'])
    parser.add_argument('--effects', nargs='+', default=list(REALISTIC))
    parser.add_argument('--series', action='store_true', help='time series (30000 samples)')
    parser.add_argument('--jobs', type=int, default=2)
    args = parser.parse_args(argv)
    cases = [(liquid, effect, scale if effect != 'none' else 0.0, seed, args.series)
             for liquid in args.liquids for effect in args.effects
             for scale in (args.scales if effect != 'none' else [0.0])
             for seed in range(args.seeds)]
    start = time.perf_counter()
    with ProcessPoolExecutor(args.jobs) as pool:
        results = list(pool.map(run_case, cases, chunksize=4))
    print('| liquid | effect | scale | correct | correct or tie | none said | '
          'median error cut | cut >= 3x or within 1.5x noise |')
    print('| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |')
    keys = sorted({c[:3] for c in cases}, key=lambda k: (k[0], args.effects.index(k[1]), k[2]))
    totals: dict[str, list[float]] = {'hit': [], 'fp': []}
    for key in keys:
        rows = [r for c, r in zip(cases, results) if c[:3] == key]
        chosen = np.array([r[0] for r in rows])
        runner = np.array([r[1] for r in rows])
        hit = float(np.mean([names(c, key[1]) for c in chosen]))
        hit_tie = float(np.mean([names(c, key[1]) or names(r, key[1])
                                 for c, r in zip(chosen, runner)]))
        none = np.mean(chosen == 'none')
        cut = np.median([r[3] / r[4] for r in rows])
        met = np.mean([r[3] >= 3 * r[4] or r[4] <= 1.5 * r[5] for r in rows])
        (totals['fp'] if key[1] == 'none' else totals['hit']).append(
            (1 - none) if key[1] == 'none' else hit_tie)
        print(f'| {key[0]} | {key[1]} | {key[2]:g} | {100 * hit:.0f} % | {100 * hit_tie:.0f} % '
              f'| {100 * none:.0f} % | {cut:.2f}x | '
              f'{"-" if key[1] == "none" else f"{100 * met:.0f} %"} |')
    print(f'\n{len(cases)} calibrations in {time.perf_counter() - start:.0f} s; '
          f'mean identification (or tie) {_percent(totals["hit"])}, '
          f'false positives {_percent(totals["fp"])}')
    return 0


if __name__ == '__main__':
    sys.exit(main())

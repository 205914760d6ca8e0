# SPDX-License-Identifier: Apache-2.0
"""
Identification and false-positive rates of ``calibrate`` on many seeded random tables.

Each case draws its own table: liquid, 24-100 points, speed and pressure ranges,
noise (a floor plus a share of the reading, up to 4x the usual), and 0, 1 or 2
effects from the whole vocabulary at random magnitudes (2-20 times the noise),
free forms with random exponents (dp^a n^b, a in 0.3-3.5, b in 0-2) and a valve
cracking at a random drop; a third of the tables get one gross bad row (+-1-2
l/min). The magnitudes and exponents are not those of the tests.

Printed: the share of injected effects named (a fitted form counts when its kind
is right; the two sensor gains count for each other, a known tie), overall and
among the effects the data can show: those that an oracle, a least-squares fit
that knows the true form (and the other true effect) and the true noise, finds
significant (p < 0.001) without the bad row; the share of tables with an effect
the data do not have (false positives, on clean tables and beside real
effects), the share of bad rows listed as outliers, and the time per table.

Run: ``.venv/bin/python bench/bench_identify_rates.py [--cases 200] [--jobs 2]``.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
import os
import time

os.environ.setdefault('OMP_NUM_THREADS', '1')
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

import numpy as np  # noqa: E402

from satmotor_ros.identify import (calibrate, CrossValidatedSelector,  # noqa: E402
                                   IdentificationError)
from satmotor_ros.identify.synthetic import (generate, Injection, Plan,  # noqa: E402
                                             with_outliers)
from satmotor_ros.model.units import LPM, MPA  # noqa: E402

GAINS = {'flow_sensor_gain', 'speed_sensor_gain'}
NAMED = ('external_leakage', 'viscosity_temperature', 'clearance_wear', 'flow_sensor_offset',
         'flow_sensor_gain', 'speed_sensor_gain', 'channel:aux')


def _injection(kind: str, rng: np.random.Generator, noise: float, plan: Plan) -> Injection:
    """Draw an injection of `kind` at 2-20 times the noise of Q_vl."""
    snr = rng.uniform(2.0, 20.0)
    if kind == 'term':
        a = float(rng.choice([0.0, rng.uniform(0.3, 3.5)]))
        b = float(rng.uniform(0.0, 2.0)) if a else float(rng.uniform(0.3, 2.0))
        expression = '*'.join(f'{n}^{p:.2f}' for n, p in (('dp', a), ('n', b)) if p)
        return Injection(f'term:{expression}', 2 * snr * noise * LPM)
    if kind == 'threshold':
        lo, hi = plan.dp_mpa
        x_c = rng.uniform(lo + 0.35 * (hi - lo), lo + 0.75 * (hi - lo)) * MPA
        shape = (('reference', x_c), ('exponent', float(rng.uniform(1.0, 2.0))))
        return Injection('threshold:dp', 2 * snr * noise * LPM, shape=shape)
    base = Injection.realistic(kind, 1.0, plan.liquid)
    return Injection.realistic(kind, snr / 8.0, plan.liquid) if base.magnitude else base


def _matches(candidate, effect: str, regressor: str) -> bool:
    """Return whether a library candidate has the injected effect's form."""
    kind = effect.partition(':')[0]
    if kind == 'term':
        names = [f.partition('^')[0] for f in effect.partition(':')[2].split('*')]
        return candidate.effect.partition(':')[0] == 'term' and candidate.regressor == '*'.join(
            names)
    if kind in ('threshold', 'channel', 'flow_sensor_offset', 'flow_sensor_gain',
                'speed_sensor_gain', 'viscosity_temperature'):
        return candidate.effect == effect
    return candidate.effect == effect and candidate.regressor == regressor


def _oracle(cal, injections, plan, table, bad) -> list[bool]:
    """Return, per injection, whether a fit that knows the true forms finds it (p < 0.001)."""
    truth = [next((c for c in cal.candidates if _matches(c, i.effect, i.regressor)), None)
             for i in injections]
    sigma = plan.noise_lpm(cal.parts.flow, cal.model) * LPM
    index = np.arange(len(cal.parts))
    if bad is not None and cal.rows is not None:
        index = index[cal.rows != bad]
    selector = CrossValidatedSelector()
    out = []
    for j, candidate in enumerate(truth):
        others = tuple(c for k, c in enumerate(truth) if k != j and c is not None)
        if candidate is None:
            out.append(False)
            continue
        try:
            base = selector.score(cal.parts, others, sigma, index)
            score = selector.score(cal.parts, (*others, candidate), sigma, index, base.fit.u_,
                                   base)
        except IdentificationError:
            out.append(False)
            continue
        out.append(score.p_value < 1e-3)
    return out


def _case(seed: int) -> tuple[list[str], list[str], bool | None, float, list[bool]]:
    rng = np.random.default_rng(1000 + seed)
    liquid = str(rng.choice(['oil', 'water']))
    low = rng.uniform(50.0, 300.0)
    plan = Plan(liquid=liquid, n_points=int(rng.integers(24, 101)),
                speed_rpm=(low, rng.uniform(low + 600.0, 1800.0)),
                dp_mpa=(rng.uniform(1.0, 5.0), rng.uniform(18.0, 28.0)),
                noise_flow_lpm=0.02 * rng.uniform(0.5, 4.0),
                noise_flow_rel=float(rng.choice([0.0005, rng.uniform(0.0, 0.004)])))
    count = int(rng.choice([0, 1, 2], p=[0.35, 0.4, 0.25]))
    pool = [*NAMED, 'term', 'threshold']
    kinds = list(rng.choice(pool, size=count, replace=False))
    if 'flow_sensor_gain' in kinds and 'speed_sensor_gain' in kinds:
        kinds.remove('speed_sensor_gain')
    noise = 0.03 * plan.noise_flow_lpm / 0.02
    injections = [_injection(k, rng, noise, plan) for k in kinds]
    table = generate(plan, injections, seed=seed)
    bad = None
    if rng.uniform() < 1 / 3:
        row = int(rng.integers(0, plan.n_points))
        table = with_outliers(table, [row], [rng.choice([-1, 1]) * rng.uniform(1.0, 2.0)])
        bad = row
    start = time.perf_counter()
    try:
        cal = calibrate(table, liquid)
    except IdentificationError:
        return ([i.effect for i in injections], ['refused'], None, time.perf_counter() - start,
                [False] * len(injections))
    took = time.perf_counter() - start
    found = [e['effect'] for e in cal.summary()['effects']]
    listed = None if bad is None else bad in [o.get('row') for o in cal.summary()['outliers']]
    return ([i.effect for i in injections], found, listed, took,
            _oracle(cal, injections, plan, table, bad))


def _kind(effect: str) -> str:
    kind = effect.partition(':')[0]
    return effect if kind == 'channel' else ('gain' if effect in GAINS else kind)


def main() -> None:
    """Run the cases and print the rates."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--cases', type=int, default=200)
    parser.add_argument('--jobs', type=int, default=2)
    args = parser.parse_args()
    start = time.perf_counter()
    with ProcessPoolExecutor(args.jobs) as pool:
        results = list(pool.map(_case, range(args.cases), chunksize=2))
    hits = injected = clean = false_clean = extra = with_effects = 0
    listed = [r[2] for r in results if r[2] is not None]
    per_kind: dict[str, list[int]] = {}
    shown: list[bool] = []
    for truth, found, _, _, oracle in results:
        truth_kinds, found_kinds = {_kind(e) for e in truth}, [_kind(e) for e in found]
        for kind, can in zip([_kind(e) for e in truth], oracle):
            per_kind.setdefault(kind, []).append(kind in found_kinds)
            if can:
                shown.append(kind in found_kinds)
        injected += len(truth_kinds)
        hits += sum(k in found_kinds for k in truth_kinds)
        if truth:
            with_effects += 1
            extra += any(k not in truth_kinds for k in found_kinds)
        else:
            clean += 1
            false_clean += bool(found)
    took = [r[3] for r in results]
    print(f'{args.cases} random tables in {time.perf_counter() - start:.0f} s '
          f'({np.median(took):.2f} s median, {np.max(took):.2f} s max per calibration)')
    print(f'identification: {100 * hits / max(injected, 1):.1f} % of {injected} injected effects '
          f'named; {100 * np.mean(shown) if shown else 0:.1f} % of the {len(shown)} that a fit '
          'knowing the true form finds (p < 0.001)')
    print(f'false positives: {100 * false_clean / max(clean, 1):.1f} % of {clean} clean tables; '
          f'an effect not injected beside real ones in {100 * extra / max(with_effects, 1):.1f} % '
          f'of {with_effects}')
    print(f'bad rows listed as outliers: {100 * np.mean(listed) if listed else 0:.1f} % of '
          f'{len(listed)}')
    for kind, got in sorted(per_kind.items()):
        print(f'  {kind}: {100 * np.mean(got):.0f} % of {len(got)}')


if __name__ == '__main__':
    main()

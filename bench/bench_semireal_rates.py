# SPDX-License-Identifier: Apache-2.0
"""
Identification and false-positive rates of ``calibrate`` on semi-real MBARI recordings.

Each case is a real trajectory (time, speed, port pressures) of one of the two vendored MBARI
logs, cropped to its high-load part and decimated to 25 Hz, with the flow of a known motor
(a family's defaults at 0.30 in^3/rev) and one or two effects injected by
:mod:`satmotor_ros.identify.semireal` (a one-sided relief valve by a law that is not the
threshold candidate's, a leak from the outflow port, wear, a flow or speed gain, a flow lag)
at 0.25, 0.5, 1 and 2 times a realistic size, plus noise measured on the same log (white,
Gaussian-correlated, spikes, and the timing jitter the logs show while the flow changes;
``--noise steady`` leaves the jitter out) and one gross bad row. The case is written as an
MBARI log and calibrated through ``satmotor calibrate --columns mbari_pto`` as a user's file.

An effect counts as named when calibration.json names its kind (the two gains count for each
other, a known tie; a lag when ``dynamics`` gives flow_lag nonzero and its excess over
speed_lag, what the data fix, within 30 % of the injected lag); a valve
counts as placed when the fitted crack pressure is within 10 % of the injected one and its
``direction`` is the injected side. Detectable: an oracle that knows the effect's
exact column and the noise's correlation finds it (t > 3.3 over every sample). Clean cases
(no effect) give the false-positive rate.

Run: ``.venv/bin/python bench/bench_semireal_rates.py [--seeds 3] [--jobs 2] [--verbose]``.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
import contextlib
from dataclasses import replace
import io
import json
import os
from pathlib import Path
import tempfile
import time

os.environ.setdefault('OMP_NUM_THREADS', '1')
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

import numpy as np  # noqa: E402

from satmotor_ros.cli import main as satmotor  # noqa: E402
from satmotor_ros.identify.semireal import (build_case, estimate_noise, KINDS,  # noqa: E402
                                            load_trajectory, realistic, ReliefValve,
                                            write_mbari_log)
from satmotor_ros.model.units import LPM  # noqa: E402

DATA = Path(__file__).resolve().parent.parent / 'test' / 'data' / 'real' / 'mbari_pto'
LOGS = {'stepped': ('2021.07.26T10.51.44.exp', 230.0, 400.0),
        'bias': ('FrictionIDMovesWithBiasCurr.exp', 240.0, 390.0)}
"""Log -> (file, start, stop [s]): the high-load part of each, where the valves and leaks act."""
STEP = 2
SCALES = (0.25, 0.5, 1.0, 2.0)
PAIRS = (('relief', 'flow_sensor_gain'), ('external_leakage', 'clearance_wear'),
         ('relief', 'flow_lag'), ('speed_sensor_gain', 'clearance_wear'))
GAINS = ('flow_sensor_gain', 'speed_sensor_gain')
WEAR = ('clearance_wear', 'leakage_wear')
CRACK_TOLERANCE = 0.10


def _spec(seed: int) -> list[tuple[str, tuple[str, ...], float, int]]:
    """Return the cases of one seed: (log, kinds, scale, seed)."""
    out = []
    for k, kind in enumerate(('none', *KINDS)):
        for j, scale in enumerate(SCALES):
            log = ('stepped', 'bias')[(seed + k + j) % 2]
            out.append((log, () if kind == 'none' else (kind,), scale, seed))
    out += [(('stepped', 'bias')[(seed + k) % 2], pair, 1.0, seed)
            for k, pair in enumerate(PAIRS)]
    return out


def _residual(case) -> np.ndarray:
    return (case.noiseless - case.displacement * case.speed) / LPM


def _detectable(trajectory, effects, kind_index: int, noise, seed: int, full) -> bool:
    """
    Return whether an oracle knowing the effect's column and the noise finds it (t > 3.3).

    The column is what the effect changes in Q - q_t n; the base model's own loss and a
    constant are partialled out (a calibration rescales the one and may offset); the fit is
    weighted by the noise's known variance per sample (its jitter part grows with |dQ/dt|), and
    the variance inflated by the noise's correlation.
    """
    others = [e for i, e in enumerate(effects) if i != kind_index]
    without = build_case(trajectory, others, noise=None, seed=seed)
    column = _residual(full) - _residual(without)
    error = (full.flow - full.noiseless) / LPM
    rate = np.gradient(full.noiseless, full.time) / LPM
    steady = noise.colored_lpm ** 2 + noise.white_lpm ** 2
    weight = 1.0 / (steady + (noise.jitter_s * rate) ** 2)
    root = np.sqrt(weight)
    base = (full.base_flow - full.displacement * trajectory.speed_state) / LPM
    nuisance = root[:, None] * np.column_stack([base, np.ones_like(base)])
    column, error = root * column, root * error
    column = column - nuisance @ np.linalg.lstsq(nuisance, column, rcond=None)[0]
    norm = float(column @ column)
    if norm < 1e-12:
        return False
    step = float(np.median(np.diff(full.time)))
    inflation = max(1.0, 2.0 * np.sqrt(np.pi) * noise.correlation_s / step)  # sum of the ACF
    return abs(1.0 + float(column @ error) / norm) * np.sqrt(norm / inflation) > 3.3


def _named(kind: str, effect, found: dict) -> tuple[bool, bool | None]:
    """Return whether `kind` is named, and for a valve whether it is placed right."""
    names = [e['effect'] for e in found['effects']]
    if kind == 'relief':
        hits = [e for e in found['effects'] if e['effect'].startswith('threshold')]
        if not hits:
            return False, False
        crack = hits[0]['threshold']['value']
        side = 'positive' if effect.direction > 0 else 'negative'
        placed = abs(crack - effect.crack) <= CRACK_TOLERANCE * effect.crack
        return True, placed and hits[0].get('direction') == side
    if kind == 'flow_lag':  # the data fix the flow lag's excess over the speed lag
        lags = {d['term']: d['coefficient'] if d.get('nonzero') else 0.0
                for d in found.get('dynamics', [])}
        excess = lags.get('flow_lag', 0.0) - lags.get('speed_lag', 0.0)
        return lags.get('flow_lag', 0.0) > 0.0 and abs(excess / effect.tau - 1.0) < 0.3, None
    if kind in GAINS:
        return any(n in GAINS for n in names), None
    if kind == 'clearance_wear':  # sliwinski2017's clearances, the other families' leakage
        return any(n in WEAR for n in names), None
    return kind in names, None


def _case(spec) -> dict:
    log, kinds, scale, seed, steady = spec
    name, start, stop = LOGS[log]
    whole = load_trajectory(DATA / name)
    noise = estimate_noise(whole)
    noise = replace(noise, jitter_s=0.0) if steady else noise
    trajectory = whole.crop(start, stop, STEP)
    rng = np.random.default_rng([seed, len(kinds), int(10 * scale)])
    direction = int(rng.choice([-1, 1]))
    effects = [realistic(k, trajectory, scale, direction=direction,
                         crack_fraction=float(rng.uniform(0.6, 0.85))) for k in kinds]
    drawn = 1000 * seed + int(100 * scale)  # each case its own noise, clean ones too
    case = build_case(trajectory, effects, noise=noise, seed=drawn, bad_rows=1)
    shown = [_detectable(trajectory, effects, i, noise, drawn, case) for i in range(len(kinds))]
    with tempfile.TemporaryDirectory() as tmp:
        path = write_mbari_log(Path(tmp) / 'case.exp', case)
        begin = time.perf_counter()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            code = satmotor(['calibrate', str(path), '--columns', 'mbari_pto', '--liquid', 'oil',
                             '--displacement', '0.30 in^3/rev', '--out', str(Path(tmp) / 'cal')])
        took = time.perf_counter() - begin
        found = json.loads((Path(tmp) / 'cal' / 'calibration.json').read_text()) if code == 0 \
            else {'effects': [], 'dynamics': []}
    named = [_named(k, e, found) for k, e in zip(kinds, effects)]
    lags = [d['term'] for d in found.get('dynamics', []) if d.get('nonzero')]
    valve = next((e for e in effects if isinstance(e, ReliefValve)), None)
    return {'log': log, 'kinds': kinds, 'scale': scale, 'seed': seed, 'code': code,
            'found': [e['effect'] for e in found['effects']], 'dynamics': lags,
            'named': named, 'shown': shown, 'took': took,
            'regions': len(found.get('missed_regions', [])),
            'inflation': found.get('variance_inflation', np.nan),
            'valve': None if valve is None else (valve.direction, valve.crack / 1e6),
            'fitted': [(e.get('direction'), round(e['threshold']['value'] / 1e6, 2))
                       for e in found['effects'] if e['effect'].startswith('threshold')]}


def _kind_of(name: str) -> str:
    """Map a calibration.json effect id to the kinds of :data:`KINDS`."""
    if name.startswith('threshold'):
        return 'relief'
    if name in WEAR:
        return 'clearance_wear'
    return 'gain' if name in GAINS else name


def main() -> None:
    """Run the cases and print the rates."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seeds', type=int, default=3)
    parser.add_argument('--jobs', type=int, default=2)
    parser.add_argument('--verbose', action='store_true', help='print every case')
    parser.add_argument('--noise', choices=('real', 'steady'), default='real',
                        help="'real': as measured on the log; 'steady': without its timing "
                             'jitter while the flow changes')
    args = parser.parse_args()
    start = time.perf_counter()
    specs = [(*s, args.noise == 'steady') for seed in range(args.seeds) for s in _spec(seed)]
    with ProcessPoolExecutor(args.jobs) as pool:
        results = list(pool.map(_case, specs))
    per_kind: dict[str, list[tuple[bool, bool]]] = {}
    placed: list[bool] = []
    clean = [r for r in results if not r['kinds']]
    extra = 0
    for r in results:
        if args.verbose:
            kinds = '+'.join(r['kinds']) or 'none'
            print(f"{r['log']:7s} seed {r['seed']} x{r['scale']:.2f} {kinds:36s} -> "
                  f"{', '.join(r['found']) or 'none'}; dynamics {r['dynamics']}; valve "
                  f"{r['valve']} fitted {r['fitted']}; detectable {r['shown']} "
                  f"({r['took']:.1f} s)")
        for kind, (hit, place), can in zip(r['kinds'], r['named'], r['shown']):
            per_kind.setdefault(kind, []).append((hit, can))
            if kind == 'relief' and hit:
                placed.append(bool(place))
        truth = {('gain' if k in GAINS else k) for k in r['kinds']}
        if r['kinds'] and any(_kind_of(f) not in truth for f in r['found']):
            extra += 1
    took = [r['took'] for r in results]
    named = [h for v in per_kind.values() for h, _ in v]
    shown = [h for v in per_kind.values() for h, c in v if c]
    print(f'{len(results)} semi-real cases in {time.perf_counter() - start:.0f} s '
          f'({np.median(took):.1f} s median, {np.max(took):.1f} s max per calibration)')
    print(f'identification: {100 * np.mean(named):.0f} % of {len(named)} injected effects named; '
          f'{100 * np.mean(shown) if shown else 0:.0f} % of the {len(shown)} detectable')
    print(f'false positives: {sum(bool(r["found"]) for r in clean)} of {len(clean)} clean cases '
          f'name an effect; {sum(bool(r["dynamics"]) for r in clean)} give a nonzero transient '
          f'term; an effect not injected beside real ones in {extra} of '
          f'{len(results) - len(clean)}')
    print(f'missed regions named on clean cases: {sum(r["regions"] for r in clean)} in '
          f'{sum(bool(r["regions"]) for r in clean)} of {len(clean)}; variance inflation of the '
          f'clean fits {np.nanmedian([r["inflation"] for r in clean]):.2f} median '
          f'({np.nanmin([r["inflation"] for r in clean]):.2f}-'
          f'{np.nanmax([r["inflation"] for r in clean]):.2f})')
    print(f'relief valves placed (crack within {100 * CRACK_TOLERANCE:.0f} %, right side): '
          f'{sum(placed)} of {len(placed)} named')
    print(f'{"kind":20s} {"named":>12s} {"detectable named":>18s}')
    for kind, got in sorted(per_kind.items()):
        can = [h for h, c in got if c]
        print(f'{kind:20s} {sum(h for h, _ in got):4d} of {len(got):3d}   '
              f'{sum(can):4d} of {len(can):3d}')
    refused = [r for r in results if r['code'] != 0]
    if refused:
        print(f'calibrate refused {len(refused)} cases')


if __name__ == '__main__':
    main()

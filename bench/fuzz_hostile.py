# SPDX-License-Identifier: Apache-2.0
"""
``make fuzz``: the property checks of test/test_fuzz_hostile.py, longer, with the outcomes counted.

Every input must end in a value, a flagged value or one line (test/fuzz_inputs.py); a failed
check, an exception of another kind, an input slower than ``--seconds`` or a peak memory
beyond ``--megabytes`` is counted as a failure and the first few are printed. Usage::

    python bench/fuzz_hostile.py [--examples N] [--cli-examples M] [--seed S]
"""

import argparse
from collections import Counter
from pathlib import Path
import resource
import sys
import tempfile
import time

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'test'))

from fuzz_inputs import (check_characteristics, check_command, check_log,  # noqa: E402
                         check_motor, check_operating_point, effect_blocks, logs, mappings,
                         motor_doc)
from hypothesis import given, HealthCheck, seed, settings, strategies as st  # noqa: E402
import yaml  # noqa: E402


def _peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


class Tally:
    """Outcomes of one check, and the first failures."""

    def __init__(self, name: str, seconds: float, megabytes: float) -> None:
        """Start counting."""
        self.name, self.seconds, self.megabytes = name, seconds, megabytes
        self.counts: Counter[str] = Counter()
        self.failures: list[str] = []
        self.slowest = 0.0

    def run(self, check, what: str) -> None:
        """Run one check and count its outcome."""
        started = time.monotonic()
        try:
            outcome = check()
        except AssertionError as err:
            outcome = 'FAILED (wrong outcome)'
            self.failures.append(f'{what[:400]}: {str(err)[:400]}')
        except Exception as err:  # noqa: B902 - a traceback is what this run looks for
            outcome = f'FAILED ({type(err).__name__})'
            self.failures.append(f'{what[:400]}: {type(err).__name__}: {str(err)[:300]}')
        spent = time.monotonic() - started
        self.slowest = max(self.slowest, spent)
        if spent > self.seconds:
            self.counts['FAILED (slower than the bound)'] += 1
            self.failures.append(f'{what[:300]}: {spent:.1f} s')
        if _peak_mb() > self.megabytes:
            self.counts['FAILED (memory beyond the bound)'] += 1
        self.counts[outcome] += 1

    def report(self) -> str:
        """One line of counts."""
        total = sum(v for k, v in self.counts.items() if not k.endswith('bound)'))
        kinds = ', '.join(f'{k} {v}' for k, v in sorted(self.counts.items()))
        return f'{self.name}: {total} inputs: {kinds}; slowest {self.slowest:.2f} s'


def main() -> int:
    """Run every check; print the counts; exit 1 if any input failed."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--examples', type=int, default=2000)
    parser.add_argument('--cli-examples', type=int, default=60)
    parser.add_argument('--seed', type=int, default=25)
    parser.add_argument('--seconds', type=float, default=60.0)
    parser.add_argument('--megabytes', type=float, default=1500.0)
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix='satmotor-fuzz-'))
    tallies = {name: Tally(name, args.seconds, args.megabytes) for name in
               ('effect file (model loading, as the nodes)', 'operating-point',
                'characteristics', 'log through a mapping', 'calibrate', 'validate')}
    quiet = settings(max_examples=args.examples, deadline=None, database=None,
                     suppress_health_check=list(HealthCheck))

    def fresh() -> Path:
        return Path(tempfile.mkdtemp(dir=work))

    @seed(args.seed)
    @quiet
    @given(effects=effect_blocks(),
           channels=st.one_of(st.none(), st.sets(st.sampled_from(('p_case', 'time', 'aux',
                                                                  'p_in', 'temperature')))))
    def motors(effects, channels):
        path = fresh() / 'motor.yaml'
        path.write_text(yaml.safe_dump(motor_doc(effects)))
        tallies['effect file (model loading, as the nodes)'].run(
            lambda: check_motor(path, repr(effects)), repr(effects))
        tallies['operating-point'].run(
            lambda: check_operating_point(path, channels and tuple(sorted(channels)),
                                          repr(effects)),
            repr(effects))

    @seed(args.seed)
    @quiet
    @given(data=st.data())
    def text_logs(data):
        text, names = data.draw(logs())
        doc = data.draw(mappings(names))
        path = fresh() / 'log.txt'
        path.write_bytes(text)
        what = repr((text[:200], doc))
        tallies['log through a mapping'].run(lambda: check_log(path, doc, what), what)

    @seed(args.seed)
    @settings(quiet, max_examples=args.cli_examples)
    @given(effects=effect_blocks())
    def curves(effects):
        where = fresh()
        (where / 'motor.yaml').write_text(yaml.safe_dump(motor_doc(effects)))
        tallies['characteristics'].run(lambda: check_characteristics(
            where / 'motor.yaml', where / 'curves', repr(effects)), repr(effects))

    @seed(args.seed)
    @settings(quiet, max_examples=args.cli_examples)
    @given(data=st.data())
    def commands(data):
        text, names = data.draw(logs())
        doc = data.draw(mappings(names))
        where = fresh()
        (where / 'log.txt').write_bytes(text)
        (where / 'map.yaml').write_text(yaml.safe_dump(doc))
        what = repr((text[:200], doc))
        for command in ('calibrate', 'validate'):
            tallies[command].run(lambda: check_command(
                command, where / 'log.txt', where / 'map.yaml', where / f'out-{command}',
                what), what)

    started = time.monotonic()
    for run in (motors, text_logs, curves, commands):
        run()
    failures = [f for t in tallies.values() for f in t.failures]
    for tally in tallies.values():
        print(tally.report())
    print(f'seed {args.seed}; {time.monotonic() - started:.0f} s; peak {_peak_mb():.0f} MB')
    for failure in failures[:10]:
        print('  ' + failure)
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())

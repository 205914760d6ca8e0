# SPDX-License-Identifier: Apache-2.0
"""
Seeded fuzz of the CSV and bag readers: one line or a result, never a traceback (issue 14).

A corpus is made in the test from real small files (the leak bench CSV, a bag of the four
calibration topics in both storages): truncations, flipped bytes, bytes set to 0xff (huge
lengths and counts), huge numbers, NaN, wrong separators, 3000 columns. Every reader must
return a result or raise its own error (DataError, BagError) with a one-line message, in
bounded time and memory.
"""

import os
from pathlib import Path
import resource
import shutil
import time

import numpy as np
import pytest

from satmotor_ros.bags import BagError, list_topics, read_series, write_bag
from satmotor_ros.identify import DataError, read_csv
from satmotor_ros.identify.bag import read_bag
from satmotor_ros.identify.columns import mapping_from_dict, read_log
from satmotor_ros.identify.textfile import read_cells
from test_bags import _inputs

BENCH = Path(__file__).parent / 'data' / 'bench_leak_water.csv'
MAPPING = mapping_from_dict({'columns': {'speed': {'column': 'speed', 'unit': 'rpm'},
                                         'flow': {'column': 'flow', 'unit': 'l/min'},
                                         'p_in': {'column': 'p_in', 'unit': 'MPa'},
                                         'p_out': {'column': 'p_out', 'unit': 'bar'}}})
CELLS = ('1e308', '-1e308', '1e400', 'nan', 'NaN', 'inf', '-inf', '', 'x', '1e-320', '9' * 400,
         '0x10', '1,5', '"', '[1]', '\x00', '1e30', '-0')
SEED = int(os.environ.get('SATMOTOR_FUZZ_SEED', '14'))  # another seed explores further
SECONDS = 5.0  # most one read may take [s]
MEGABYTES = 600  # most the corpus may add to the peak memory [MB]


def _mutations(data: bytes, rng: np.random.Generator, count: int) -> list[bytes]:
    """Return `count` damaged copies of `data`: truncated, bytes flipped or set to 0xff."""
    out = []
    for i in range(count):
        buf = bytearray(data)
        kind = i % 3
        if kind == 0:
            out.append(bytes(buf[:int(rng.integers(0, len(buf)))]))
            continue
        at = rng.integers(0, len(buf), size=int(rng.integers(1, 33)))
        for a in at:
            buf[a] = 0xff if kind == 2 else buf[a] ^ int(rng.integers(1, 256))
        out.append(bytes(buf))
    return out


def _csv_corpus(rng: np.random.Generator) -> list[bytes]:
    text = BENCH.read_text()
    lines = text.splitlines()
    corpus = [text.encode(), b'', b'\xef\xbb\xbf' + text.encode(), lines[0].encode() + b'\n',
              b'\xff\xfe' + text.encode(), '\n'.join(lines[:3]).encode()]
    corpus += _mutations(text.encode(), rng, 120)
    for _ in range(120):  # one bad cell
        rows = [line.split(',') for line in lines]
        r, c = int(rng.integers(0, len(rows))), int(rng.integers(0, len(rows[0])))
        rows[r][c] = CELLS[int(rng.integers(0, len(CELLS)))]
        corpus.append('\n'.join(','.join(row) for row in rows).encode())
    for sep in (';', '\t', ' ', '|', ',,'):
        corpus.append(text.replace(',', sep).encode())
        corpus.append('\n'.join(line.replace(',', sep) if i % 2 else line
                                for i, line in enumerate(lines)).encode())
    wide = [line + ''.join(f',c{i} [V]' if not n else ',1' for i in range(2992))
            for n, line in enumerate(lines[:20])]
    corpus.append('\n'.join(wide).encode())
    corpus.append(('\n'.join(lines) + '\n' + ',' * 3000).encode())
    corpus.append(b'#' + text.encode())
    corpus.append(('\n'.join(lines[:1] + [lines[1]] * 5000)).encode())
    return corpus


def _check(read, *args):
    """Read; pass on a result or a one-line reader error, fail on anything else or slowness."""
    start = time.perf_counter()
    try:
        read(*args)
    except (DataError, BagError) as err:
        assert '\n' not in str(err) and len(str(err)) < 2000, str(err)[:300]
    assert time.perf_counter() - start < SECONDS, f'{read.__name__} took too long'


@pytest.fixture(scope='module')
def memory():
    """Check the whole corpus stays within :data:`MEGABYTES` of extra peak memory."""
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    yield
    grown = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024
    assert grown < MEGABYTES


def test_csv_readers_never_raise_anything_else(tmp_path, memory):
    rng = np.random.default_rng(SEED)
    path = tmp_path / 'fuzz.csv'
    for data in _csv_corpus(rng):
        path.write_bytes(data)
        _check(read_csv, path)
        _check(read_log, path, MAPPING)
        for separator in ('auto', 'semicolon', 'whitespace'):
            _check(read_cells, path, separator)


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_bag_readers_never_raise_anything_else(tmp_path, memory, storage):
    rng = np.random.default_rng(SEED + (storage == 'sqlite3'))
    good = tmp_path / 'good'
    write_bag(good, _inputs(rng)['topics'], storage=storage)
    read_bag(good)  # the unharmed bag is a calibration table
    storage_file = next(p for p in good.iterdir() if p.name != 'metadata.yaml')
    meta = (good / 'metadata.yaml').read_bytes()
    damaged = _mutations(storage_file.read_bytes(), rng, 90)
    cases = [(storage_file.name, data) for data in damaged]
    cases += [('metadata.yaml', data) for data in _mutations(meta, rng, 30)]
    cases.append(('metadata.yaml', meta.replace(b'message_count: 200',
                                                b'message_count: ' + b'9' * 400)))
    for i, (name, data) in enumerate(cases):
        bag = tmp_path / f'bag{i}'
        shutil.copytree(good, bag)
        (bag / name).write_bytes(data)
        _check(read_bag, bag)
        _check(list_topics, bag)
        _check(read_series, bag, ['flow_command', 'joint_states'])
        shutil.rmtree(bag)

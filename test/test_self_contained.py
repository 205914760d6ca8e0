# SPDX-License-Identifier: Apache-2.0
"""The suite reads nothing outside the repository: a fresh clone alone runs it."""

from pathlib import Path
import re

import conftest

TEST = Path(__file__).resolve().parent


def test_no_test_file_names_a_path_beside_the_repository():
    pattern = re.compile(r"\.\./shared|parents\[[2-9]\]|['\"]/work/")
    offenders = [f'{path.name}:{number}' for path in sorted(TEST.rglob('*.py'))
                 for number, line in enumerate(path.read_text(encoding='utf-8').splitlines(), 1)
                 if pattern.search(line) and path.name != 'test_self_contained.py']
    assert offenders == []


def test_a_read_beside_the_repository_is_noted(tmp_path):
    clone, shared = tmp_path / 'clone', tmp_path / 'shared'
    (clone / 'test').mkdir(parents=True)
    shared.mkdir()
    for path in (clone / 'test' / 'a.csv', shared / 'a.csv'):
        path.write_text('x')
    assert conftest.read_beside(str(shared / 'a.csv'), clone)
    assert not conftest.read_beside(str(clone / 'test' / 'a.csv'), clone)
    assert not conftest.read_beside(str(shared / 'absent.cfg'), clone)
    assert not conftest.read_beside(str(tmp_path.parent / 'elsewhere'), clone)
    (tmp_path / 'pytest-of-root').mkdir()  # a clone under /tmp has tmp_path beside it
    (tmp_path / 'pytest-of-root' / 'b.csv').write_text('x')
    assert not conftest.read_beside(str(tmp_path / 'pytest-of-root' / 'b.csv'), clone)


def test_the_audit_hook_notes_a_real_open(tmp_path, monkeypatch):
    clone, shared = tmp_path / 'clone', tmp_path / 'shared'
    clone.mkdir()
    shared.mkdir()
    (shared / 'log.exp').write_text('x')
    monkeypatch.setattr(conftest, 'REPOSITORY', clone)
    with open(shared / 'log.exp', encoding='utf-8'):
        pass
    noted = list(conftest._read_outside)
    conftest._read_outside.clear()  # this test's own read is not a failure of it
    assert noted == [str(shared / 'log.exp')]


def test_the_vendored_data_carry_their_licences():
    data = TEST / 'data'
    licence = (data / 'real' / 'mbari_pto' / 'LICENSE.mbari_wec_gz').read_text()
    assert licence.split()[:4] == ['Apache', 'License', 'Version', '2.0,']
    assert 'MIT License' in (data / 'foreign_bags' / 'LICENSES.md').read_text()
    assert '`foreign_bags/`' in (data / 'README.md').read_text()

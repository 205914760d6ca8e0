# SPDX-License-Identifier: Apache-2.0
"""The docs say what the code does: example outputs under out/, citations that resolve."""

from pathlib import Path
import re
import shlex

import pytest

from satmotor_ros.cli import main

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / 'README.md', *sorted((ROOT / 'doc').glob('*.md'))]
OUTPUTS = ('--out', '--out-bag', '--plot')


def _commands(path):
    """Yield the example command lines of a Markdown file's sh blocks."""
    text = path.read_text(encoding='utf-8')
    for block in re.findall(r'```sh\n(.*?)```', text, re.S):
        joined = block.replace('\\\n', ' ')
        for line in joined.splitlines():
            line = line.split('  #')[0].strip()
            if line.startswith(('satmotor ', '$S ', 'python -m satmotor_ros')):
                yield line


@pytest.mark.parametrize('path', DOCS, ids=lambda p: p.name)
def test_example_commands_write_under_out(path):
    for line in _commands(path):
        words = shlex.split(line)
        for flag, value in zip(words, words[1:]):
            if flag in OUTPUTS:
                assert value.startswith('out/'), f'{path.name}: {line}'


def test_the_paper_model_sheet_cited_is_in_the_repository():
    sheet = ROOT / 'doc' / 'PAPER_MODEL.md'
    assert 'Provenance' in sheet.read_text(encoding='utf-8')[:600]
    cited = [p for p in [*DOCS, *ROOT.glob('satmotor_ros/**/*.py'), *ROOT.glob('test/*.py')]
             if 'PAPER_MODEL.md' in p.read_text(encoding='utf-8')
             and p.resolve() not in (sheet.resolve(), Path(__file__).resolve())]
    assert cited
    for path in cited:
        for match in re.finditer(r'[\w./]*PAPER_MODEL\.md', path.read_text(encoding='utf-8')):
            name = match.group(0)
            base = path.parent if path.suffix == '.md' else ROOT
            assert (base / name).resolve() == sheet.resolve() or name == 'PAPER_MODEL.md' \
                and path.parent == sheet.parent, f'{path}: {name}'


def test_a_negative_flow_is_no_error_as_doc_model_says(capsys):
    assert main(['operating-point', '--flow', '-5', '--dp', '10']) == 0
    assert "--flow '-5'" not in (ROOT / 'doc' / 'model.md').read_text(encoding='utf-8')
    assert main(['operating-point', '--flow', 'x', '--dp', '10']) == 1
    err = capsys.readouterr().err
    assert err.strip() in (ROOT / 'doc' / 'model.md').read_text(encoding='utf-8').replace(
        '\n', ' ')


def test_doc_validate_says_what_validate_does():
    text = (ROOT / 'doc' / 'validate.md').read_text(encoding='utf-8')
    assert 'files already there are replaced' not in text and '--force' in text
    assert 'no forward flow, negative speed' not in text and 'reverse rows' in text.lower()
    assert 'transient' in text

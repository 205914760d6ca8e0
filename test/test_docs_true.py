# SPDX-License-Identifier: Apache-2.0
"""The docs say what the code does: example outputs under out/, citations that resolve."""

import json
from pathlib import Path
import re
import shlex

import pytest

from satmotor_ros.cli import main

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / 'README.md', *sorted((ROOT / 'doc').glob('*.md'))]
OUTPUTS = ('--out', '--out-bag', '--plot')
MBARI = ('2021.07.26T10.51.44.exp', 'FrictionIDMovesWithBiasCurr.exp')  # as conftest.py's


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


def _spaced(count):
    """Write a count as the README does: 21 129."""
    return f'{count:,}'.replace(',', ' ')


def _mbari(mbari_calibrations, name):
    out = mbari_calibrations[name].out  # conftest.py: both logs calibrated once a session
    return json.loads((out / 'calibration.json').read_text(encoding='utf-8'))


@pytest.mark.slow  # mbari_calibrations: both real logs calibrated
@pytest.mark.parametrize('name', MBARI)
def test_the_readme_gives_each_mbari_logs_figures_as_calibrate_writes_them(mbari_calibrations,
                                                                           name):
    result = _mbari(mbari_calibrations, name)
    readme = (ROOT / 'README.md').read_text(encoding='utf-8')
    row = next(line for line in readme.splitlines() if line.startswith(f'| `{name}`'))
    cover = result['coverage']
    assert f"| {_spaced(cover['samples_used'])} of {_spaced(cover['samples_total'])} |" in row
    (valve,) = [e for e in result['effects'] if e['effect'].startswith('threshold:')]
    assert f"`{valve['name']}`" in row  # the one name, with its side and crack
    low, high = (v / 1e6 for v in valve['threshold']['ci95'])
    assert f'{low:.2f}–{high:.2f}), exponent {valve["exponent"]:.2f}' in row
    response = valve['response_time']  # read at every sample, a valve may lag its law
    assert (f"response time {response['seconds']:.2f} s ({response['ci95'][0]:.2f}–"
            f"{response['ci95'][1]:.2f})" in row if response['seconds'] > 0.0
            else 'no response time (the law itself)' in row)
    # the flow at full drop as the output gives it: at the rows' top, and the law at the
    # samples' top, where it outruns the flow measured
    reach = valve['full_drop']
    assert (f"passing {reach['fitted_flow_lpm']:.1f} l/min at the highest drop of the rows it "
            f"was fitted on ({reach['fitted_dp_mpa']:.2f} MPa)") in row
    assert (f"its law gives {reach['flow_lpm']:.2g} l/min at {reach['data_dp_mpa']:.2f} MPa, "
            f"where {reach['measured_flow_lpm']:.1f} l/min were measured") in row
    assert ('(extrapolated;' in row) == reach['extrapolated']
    assert f"exceeds the flow measured at {reach['above_measured']} samples" in row
    before, after = result['error_before']['rmse_lpm'], result['error_after']['rmse_lpm']
    assert row.rstrip().endswith(
        f'| {before:.3f} → {after:.3f} ('
        f"{result['error_before_with_outliers']['rmse_lpm']:.3f} → "
        f"{result['error_after_with_outliers']['rmse_lpm']:.3f}" + (
            ' with outliers) |' if name == MBARI[0] else ') |'))


@pytest.mark.slow  # mbari_calibrations: both real logs calibrated
def test_the_docs_counts_of_the_2021_log_are_the_outputs(mbari_calibrations):
    result = _mbari(mbari_calibrations, MBARI[0])
    readme = (ROOT / 'README.md').read_text(encoding='utf-8')
    doc = (ROOT / 'doc' / 'calibration.md').read_text(encoding='utf-8')
    regions = len(result['missed_regions'])
    assert re.search(rf'On the 2021 log `missed_regions` lists {regions} regions\b', readme)
    windows = int(re.search(r'whose (\d+) steady windows', result['mode_reason']).group(1))
    assert f'gives {windows}\nusable steady windows' in doc
    assert f'(`Mode transient: {result["mode_reason"].split(": every")[0]}' in \
        doc.replace('\n', ' ')
    shares = [int(re.search(r'hold (\d+) % of the samples', _mbari(mbari_calibrations, n)[
        'mode_reason']).group(1)) for n in MBARI]
    assert f'their steady windows hold {min(shares)}–{max(shares)} % of\nthe samples' in readme

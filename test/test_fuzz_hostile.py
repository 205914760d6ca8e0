# SPDX-License-Identifier: Apache-2.0
"""
Property tests of hostile effect files, column mappings and logs (issue 25).

Each ends in a value, a flagged value or one line; ``make fuzz`` runs the same checks longer
(bench/fuzz_hostile.py) and counts the outcomes.
"""

from pathlib import Path
import tempfile

from fuzz_inputs import (check_command, check_log, check_motor, check_operating_point,
                         effect_blocks, logs, mappings, motor_doc, OUTCOMES)
from hypothesis import example, given, HealthCheck, settings, strategies as st
import pytest
import yaml

SETTINGS = settings(max_examples=50, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture,
                                           HealthCheck.too_slow])


def _fresh(tmp_path: Path) -> Path:
    return Path(tempfile.mkdtemp(dir=tmp_path))


@SETTINGS
@given(effects=effect_blocks())
@example(effects={'term:dp^.': {'coefficient': 1.0}})  # issue 25 item 5
@example(effects={'term:dp^1.2.3': {'coefficient': 1.0}})
def test_an_effect_file_loads_to_a_model_or_one_line(tmp_path, effects):
    path = _fresh(tmp_path) / 'motor.yaml'
    path.write_text(yaml.safe_dump(motor_doc(effects)))
    assert check_motor(path, repr(effects)) in OUTCOMES


@settings(SETTINGS, max_examples=40)
@given(effects=effect_blocks(), channels=st.one_of(st.none(), st.sets(st.sampled_from(
    ('p_case', 'time', 'aux', 'p_in', 'temperature')))))
def test_operating_point_on_an_effect_file_is_a_point_or_one_line(tmp_path, effects, channels):
    path = _fresh(tmp_path) / 'motor.yaml'
    path.write_text(yaml.safe_dump(motor_doc(effects)))
    given = None if channels is None else tuple(sorted(channels))
    assert check_operating_point(path, given, repr(effects)) in OUTCOMES


@SETTINGS
@given(data=st.data())
def test_a_log_read_through_a_mapping_is_a_table_or_one_line(tmp_path, data):
    text, names = data.draw(logs())
    doc = data.draw(mappings(names))
    path = _fresh(tmp_path) / 'log.txt'
    path.write_bytes(text)
    assert check_log(path, doc, repr((text[:300], doc))) in OUTCOMES


@pytest.mark.parametrize('command', ['calibrate', 'validate'])
@settings(SETTINGS, max_examples=8)
@given(data=st.data())
def test_calibrate_and_validate_on_hostile_logs(tmp_path, command, data):
    text, names = data.draw(logs())
    doc = data.draw(mappings(names))
    where = _fresh(tmp_path)
    (where / 'log.txt').write_bytes(text)
    (where / 'map.yaml').write_text(yaml.safe_dump(doc))
    outcome = check_command(command, where / 'log.txt', where / 'map.yaml', where / 'out',
                            repr((text[:300], doc)))
    assert outcome in OUTCOMES

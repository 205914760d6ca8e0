# SPDX-License-Identifier: Apache-2.0
"""
Where the tests find the real logs and foreign bags vendored under test/data (see its README).

A test that needs them calls :func:`data_path` inside the test (not at collection), so that a
missing file fails that test with one clear line instead of skipping it.
"""

from pathlib import Path

import pytest

DATA = Path(__file__).resolve().parent / 'data'
"""test/data: vendored copies with their licences and provenance."""

FOREIGN_BAGS = (
    'nometa_filecompressed_split4', 'nometa_msgcompressed_split4', 'nometa_split3_talker',
    'v1_crystal_cdr_test', 'v3_cdr_test_type_mismatch', 'v4_empty', 'v4_empty_zstd_file',
    'v4_talker_2020', 'v4_talker_dbschema4_qos_edited', 'v4_talker_mcap_gocli',
    'v4_test_msgs_strings', 'v4_wbag_split5', 'v5_humble_geometry_mcap',
    'v5_humble_sensor_mcap', 'v5_humble_sensor_sqlite3', 'v5_nebula_radar_custom',
    'v5_nebula_vlp32_empty_qos', 'v6_wrong_format_mcap', 'v7_cdr_test_mcap',
    'v7_cdr_test_sqlite3', 'v8_services_mcap', 'v8_services_sqlite3', 'v9_actions_mcap',
    'v9_actions_sqlite3',
)
"""The 24 bags of test/data/foreign_bags (its README describes each)."""


def data_path(*parts: str) -> Path:
    """
    Return a path under test/data, failing the calling test when it is not there.

    Parameters
    ----------
    *parts : str
        Path components below test/data, [-]

    Returns
    -------
    pathlib.Path
        The existing path.

    """
    path = DATA.joinpath(*parts)
    if not path.exists():
        pytest.fail(f'{path} is missing from the repository', pytrace=False)
    return path


def foreign_bag(name: str) -> Path:
    """
    Return the directory of one foreign bag (see :data:`FOREIGN_BAGS`).

    Parameters
    ----------
    name : str
        The bag's directory name, [-]

    Returns
    -------
    pathlib.Path
        test/data/foreign_bags/<name>.

    """
    return data_path('foreign_bags', name)

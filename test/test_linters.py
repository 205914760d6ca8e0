# SPDX-License-Identifier: Apache-2.0
"""
ament's Python linters, run as tests the way ``colcon test`` runs them, and mypy.

Both ament linters check the package from the repository root.  Directories whose names
start with ``.`` or ``_`` (``.venv``, ``.git``, ``__pycache__``) are skipped by the linters
themselves; the build and output trees are excluded here.  mypy checks satmotor_ros/ as
mypy.ini says (strict).
"""

from pathlib import Path

from ament_flake8.main import main_with_errors
from ament_pep257.main import main as pep257_main
from mypy import api as mypy_api
import pytest

REPO_ROOT = Path(__file__).resolve().parent.parent
EXCLUDED_DIRS = ['build', 'install', 'log', 'out']


@pytest.mark.flake8
@pytest.mark.linter
def test_flake8(monkeypatch):
    """Code passes ament_flake8: 99 columns, google import order, single quotes."""
    monkeypatch.chdir(REPO_ROOT)
    rc, errors = main_with_errors(argv=['--exclude', *EXCLUDED_DIRS])
    assert rc == 0, \
        'Found %d code style errors / warnings:\n' % len(errors) + '\n'.join(errors)


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257(monkeypatch):
    """Docstrings pass ament_pep257, pydocstyle with ament's ignore list."""
    monkeypatch.chdir(REPO_ROOT)
    excludes = [str(REPO_ROOT / name) for name in EXCLUDED_DIRS]
    rc = pep257_main(argv=['.', '--exclude', *excludes])
    assert rc == 0, 'Found code style errors / warnings'


@pytest.mark.linter
def test_mypy(monkeypatch):
    """The package type-checks under mypy.ini (strict): no error, no unused ignore."""
    monkeypatch.chdir(REPO_ROOT)
    stdout, stderr, rc = mypy_api.run(['--config-file', str(REPO_ROOT / 'mypy.ini')])
    assert rc == 0, f'mypy found errors:\n{stdout}{stderr}'
    assert 'Success: no issues found' in stdout, stdout

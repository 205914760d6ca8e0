# SPDX-License-Identifier: Apache-2.0
"""
Test-session setup shared by every test.

pytest imports this file before it collects any test module or doctest, so the ROS
environment below is in place before anything can import rclpy; subprocesses that the
tests start inherit it.
"""

import contextlib
import io
import os
from pathlib import Path
import sys
import tempfile
from types import SimpleNamespace

import pytest

# Discovery never leaves this machine, whatever the calling shell says.
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

# A domain of the test session's own, unless the caller (Makefile, .ci/run) chose one.
# ROS documents 0..101 as the ids that are safe on Linux (higher ids reach into the
# ephemeral port range), and 0 is everyone's default, so use 1..101.
if not os.environ.get('ROS_DOMAIN_ID'):
    os.environ['ROS_DOMAIN_ID'] = str(1 + os.getpid() % 101)


REPOSITORY = Path(__file__).resolve().parents[1]
_read_outside: list[str] = []


def read_beside(path: str, repository: Path) -> bool:
    """
    Tell whether opening ``path`` reads a file beside ``repository`` that a clone lacks.

    That is shared/ beside it, or any other sibling but the temporary directory (a clone
    under /tmp has pytest's tmp_path beside it).
    """
    path = os.path.abspath(path)
    if path.startswith(str(repository) + os.sep) or not os.path.exists(path):
        return False  # a tool probing for a config file that is not there reads nothing
    if path.startswith(str(repository.parent / 'shared') + os.sep):
        return True
    return (path.startswith(str(repository.parent) + os.sep)
            and not path.startswith(tempfile.gettempdir() + os.sep))


def _note_reads_beside_the_repository(event, args):
    # shared/ and any other sibling of the clone is what a user's clone does not have.
    if event == 'open' and isinstance(args[0], str) and read_beside(args[0], REPOSITORY):
        _read_outside.append(args[0])


sys.addaudithook(_note_reads_beside_the_repository)


def pytest_collection_modifyitems(items):
    """Mark every test that uses a ROS fixture ``ros`` (pytest.ini), wherever it is."""
    for item in items:
        if {'harness', 'ros'} & set(getattr(item, 'fixturenames', ())):
            item.add_marker(pytest.mark.ros)


@pytest.fixture(autouse=True)
def _self_contained():
    """Fail a test that opened a file beside the repository (a user's clone has none)."""
    _read_outside.clear()
    yield
    if _read_outside:
        pytest.fail(f'read outside the repository: {_read_outside[0]}', pytrace=False)


@pytest.fixture()
def harness():
    """Give a test its own Context, node and executor, shut down afterwards."""
    from node_harness import Harness  # imports rclpy: only after the environment above
    h = Harness()
    try:
        yield h
    finally:
        h.close()


@pytest.fixture()
def ros(request):
    """
    Give a fresh context, an executor on it and a probe node; shut all down afterwards.

    The probe lives in the test module's ``NAMESPACE`` (the root without one). Yields
    ``(context, executor, probe)``.
    """
    import rclpy  # only after the environment above
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    context = Context()
    context.init()
    executor = SingleThreadedExecutor(context=context)
    probe = rclpy.create_node('probe', namespace=getattr(request.module, 'NAMESPACE', '/'),
                              context=context)
    executor.add_node(probe)
    try:
        yield context, executor, probe
    finally:
        executor.shutdown()
        probe.destroy_node()
        context.try_shutdown()


MBARI = ('2021.07.26T10.51.44.exp', 'FrictionIDMovesWithBiasCurr.exp')
"""The two real MBARI power-take-off logs (test/data/real/mbari_pto)."""


@pytest.fixture(scope='session')
def mbari_calibrations(tmp_path_factory):
    """
    Calibrate both MBARI logs once per session through ``satmotor calibrate``.

    With the Parker F11-5's displacement (0.30 in^3/rev). Gives name -> namespace of
    ``code``, ``out``, ``err`` (the command's exit status, --out and stderr) and ``call``,
    the positional arguments the command passed to :func:`identify.calibrate` (the table
    read, the liquid, the spec, the options), and ``calibration``, what it returned.
    """
    from satmotor_ros.cli import calibrate as command
    from satmotor_ros.cli.main import main
    from vendored_data import data_path
    runs = {}
    for name in MBARI:
        seen = []

        def recorded(*args, **kwargs):
            seen.append((args, kwargs, plain(*args, **kwargs)))
            return seen[-1][2]

        plain = command.calibrate
        out = tmp_path_factory.mktemp('cal') / name
        errors = io.StringIO()
        with pytest.MonkeyPatch.context() as patch, contextlib.redirect_stderr(errors):
            patch.setattr(command, 'calibrate', recorded)
            code = main(['calibrate', str(data_path('real', 'mbari_pto', name)),
                         '--columns', 'mbari_pto', '--liquid', 'oil',
                         '--displacement', '0.30 in^3/rev', '--out', str(out)])
        assert len(seen) == 1 and not seen[0][1], seen
        runs[name] = SimpleNamespace(code=code, out=out, err=errors.getvalue(),
                                     call=seen[0][0], calibration=seen[0][2])
    return runs

# SPDX-License-Identifier: Apache-2.0
"""
The package builds with colcon and with pip, and runs the way ``ros2 run`` runs it.

colcon builds a copy of the source tree, so the checkout gets no ``build/`` or
``*.egg-info``, into colcon's default isolated layout (``<install>/satmotor_ros``).
The executable is then found as ``ros2 run`` finds it (ros2cli ``ros2run/api``:
``get_package_prefix`` from the ament index, then an executable file of that name under
``<prefix>/lib/<package>``), and run with the environment that sourcing the install's
setup script would give (its ``share/<package>/package.dsv`` hooks).
"""

import json
import os
from pathlib import Path
import shutil
import signal
import subprocess
import sys
import zipfile

from ament_index_python.packages import get_package_prefix
import pytest

PACKAGE = 'satmotor_ros'
REPO_ROOT = Path(__file__).resolve().parent.parent
BUILD_TIMEOUT = 180.0  # a clean build takes a few seconds, [s]
RUN_TIMEOUT = 60.0  # one CLI call, [s]

# Top-level entries of a checkout that are not package source.
NOT_SOURCE = {'.git', '.venv', '.pytest_cache', '.hypothesis', 'build', 'install', 'log', 'out'}


def _ignore_non_source(directory, names):
    """
    Tell shutil.copytree what to leave out of the source copy.

    Parameters
    ----------
    directory : str
        Directory being copied, [-]
    names : list of str
        Its entries, [-]

    Returns
    -------
    set of str
        Entries not to copy, [-]

    """
    skipped = {n for n in names if n == '__pycache__' or n.endswith('.egg-info')}
    if Path(directory) == REPO_ROOT:
        skipped |= NOT_SOURCE & set(names)
    return skipped


def _copy_source(destination):
    """
    Copy the package source into ``destination``.

    Parameters
    ----------
    destination : pathlib.Path
        Directory to create, [-]

    Returns
    -------
    pathlib.Path
        The copy's root, [-]

    """
    shutil.copytree(REPO_ROOT, destination, ignore=_ignore_non_source)
    return destination


def _find_tool(name):
    """
    Locate a console script of this interpreter's environment, else on PATH.

    Parameters
    ----------
    name : str
        Script name, [-]

    Returns
    -------
    str
        Path of the script, [-]

    """
    beside = Path(sys.executable).parent / name
    if beside.is_file() and os.access(beside, os.X_OK):
        return str(beside)
    found = shutil.which(name)
    if found is None:
        pytest.fail(f'{name} not found beside {sys.executable} nor on PATH')
    return found


def _prepend(env, name, value):
    """
    Prepend ``value`` to a path-list variable unless it is already there.

    Parameters
    ----------
    env : dict
        Environment to change, [-]
    name : str
        Variable name, [-]
    value : str
        Path to add, [-]

    """
    parts = [p for p in env.get(name, '').split(os.pathsep) if p]
    if value not in parts:
        env[name] = os.pathsep.join([value, *parts])


def _sourced_environment(prefix, base):
    """
    Build the environment that sourcing the package's install would give.

    colcon writes ``share/<package>/package.dsv``, which lists hook files whose lines read
    ``prepend-non-duplicate;NAME;RELATIVE_PATH``; its setup scripts apply them.

    Parameters
    ----------
    prefix : pathlib.Path
        The package's install prefix, [-]
    base : dict
        Environment to start from, [-]

    Returns
    -------
    dict
        The new environment, [-]

    """
    env = dict(base)
    package_dsv = prefix / 'share' / PACKAGE / 'package.dsv'
    for line in package_dsv.read_text().splitlines():
        kind, _, hook = line.partition(';')
        if kind != 'source' or not hook.endswith('.dsv'):
            continue
        for hook_line in (prefix / hook).read_text().splitlines():
            if not hook_line.strip():
                continue
            action, name, value = hook_line.split(';', 2)
            if action not in ('prepend-non-duplicate', 'prepend-non-duplicate-if-exists'):
                pytest.fail(f'unhandled colcon environment hook {hook_line!r} in {hook}')
            path = prefix / value if value else prefix
            if action.endswith('-if-exists') and not path.exists():
                continue
            _prepend(env, name, str(path))
    return env


def _executable_path(package_name, executable_name):
    """
    Find an executable of a package as ros2run's ``get_executable_path`` does.

    Parameters
    ----------
    package_name : str
        Package to look in, [-]
    executable_name : str
        File name of the executable, [-]

    Returns
    -------
    pathlib.Path or None
        The executable, or None when the package has none of that name, [-]

    """
    base_path = os.path.join(get_package_prefix(package_name), 'lib', package_name)
    matches = []
    for dirpath, dirnames, filenames in os.walk(base_path):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith('.'))
        for filename in sorted(filenames):
            path = os.path.join(dirpath, filename)
            if os.access(path, os.X_OK) and filename == executable_name:
                matches.append(Path(path))
    assert len(matches) <= 1, f'several executables named {executable_name}: {matches}'
    return matches[0] if matches else None


def start_installed(env, cwd, namespace, name, *ros_args):
    """Start installed executable `name` as ``ros2 run`` would, in `namespace`; output piped."""
    executable = _executable_path(PACKAGE, name)
    assert executable is not None, f'{name} is not installed'
    return subprocess.Popen(
        [str(executable), '--ros-args', '-r', f'__ns:={namespace}', *ros_args], cwd=cwd,
        env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def stop_process(process):
    """Stop `process` with SIGINT (kill after 10 s); return its exit code and output."""
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(timeout=10.0)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
    return process.returncode, process.stdout.read()


@pytest.fixture(scope='module')
def colcon_build(tmp_path_factory):
    """
    Build a copy of the package with colcon into a temporary workspace.

    Returns
    -------
    dict
        ``install``: the install base; ``prefix``: the package's prefix in it;
        ``repo_before``: the checkout's top-level entries before the build, [-]

    """
    workspace = tmp_path_factory.mktemp('colcon_ws')
    repo_before = sorted(os.listdir(REPO_ROOT))
    source = _copy_source(workspace / 'src' / PACKAGE)
    install = workspace / 'install'
    env = dict(os.environ)
    env['COLCON_HOME'] = str(workspace / 'colcon_home')  # no user defaults.yaml
    cmd = [
        _find_tool('colcon'), '--log-base', str(workspace / 'log'),
        'build', '--base-paths', str(source.parent),
        '--build-base', str(workspace / 'build'), '--install-base', str(install),
        '--event-handlers', 'console_direct+',
    ]
    proc = subprocess.run(
        cmd, cwd=workspace, env=env, capture_output=True, text=True, timeout=BUILD_TIMEOUT)
    assert proc.returncode == 0, f'colcon build failed:\n{proc.stdout}\n{proc.stderr}'
    return {'install': install, 'prefix': install / PACKAGE, 'repo_before': repo_before,
            'output': proc.stdout + proc.stderr}


@pytest.fixture()
def sourced_install(colcon_build, monkeypatch):
    """
    Put the built package on AMENT_PREFIX_PATH and PYTHONPATH, as sourcing it would.

    Returns
    -------
    dict
        The environment for subprocesses, [-]

    """
    env = _sourced_environment(colcon_build['prefix'], os.environ)
    monkeypatch.setenv('AMENT_PREFIX_PATH', env['AMENT_PREFIX_PATH'])
    return env


def _run(argv, env, cwd):
    """
    Run a command of the installed package.

    Parameters
    ----------
    argv : list of str
        Command and arguments, [-]
    env : dict
        Its environment, [-]
    cwd : pathlib.Path
        Its working directory (not the checkout, whose source would shadow the install), [-]

    Returns
    -------
    subprocess.CompletedProcess
        The finished process, [-]

    """
    return subprocess.run(
        [str(a) for a in argv], cwd=cwd, env=env, capture_output=True, text=True,
        timeout=RUN_TIMEOUT)


def test_colcon_build_installs_index_marker_manifest_and_config(colcon_build):
    """The install holds what ament and the nodes look up, and no setuptools errors."""
    prefix = colcon_build['prefix']
    assert (prefix / 'share/ament_index/resource_index/packages' / PACKAGE).is_file()
    assert (prefix / 'share' / PACKAGE / 'package.xml').is_file()
    source_yaml = sorted(p.name for p in (REPO_ROOT / 'config').glob('*.yaml'))
    assert source_yaml, 'config/ holds no *.yaml'
    share_yaml = sorted(p.name for p in (prefix / 'share' / PACKAGE / 'config').glob('*.yaml'))
    assert share_yaml == source_yaml
    site = f'lib/python{sys.version_info.major}.{sys.version_info.minor}/site-packages'
    package_data = prefix / site / PACKAGE / 'config'
    assert sorted(p.name for p in package_data.glob('*.yaml')) == source_yaml
    assert (prefix / site / PACKAGE / 'py.typed').is_file()
    problems = [line for line in colcon_build['output'].splitlines()
                if line.lstrip().lower().startswith('error') or 'Traceback' in line]
    assert not problems, colcon_build['output']


def test_colcon_build_leaves_the_checkout_untouched(colcon_build):
    """A build from a copy writes no build/, install/, log/ or *.egg-info into the repo."""
    new_entries = set(os.listdir(REPO_ROOT)) - set(colcon_build['repo_before'])
    assert not {name for name in new_entries if not name.startswith('.')}, new_entries


def test_ament_index_finds_satmotor_executable_like_ros2_run(colcon_build, sourced_install):
    """get_package_prefix leads to an executable lib/satmotor_ros/satmotor."""
    assert Path(get_package_prefix(PACKAGE)) == colcon_build['prefix']
    path = _executable_path(PACKAGE, 'satmotor')
    assert path == colcon_build['prefix'] / 'lib' / PACKAGE / 'satmotor'


def test_installed_satmotor_imports_the_install_tree(colcon_build, sourced_install, tmp_path):
    """The executable's interpreter loads satmotor_ros and its metadata from the install."""
    script = _executable_path(PACKAGE, 'satmotor')
    shebang = script.read_text().splitlines()[0]
    assert shebang.startswith('#!'), shebang
    interpreter = shebang[2:].strip().split()[0]
    probe = (
        'import importlib.metadata, importlib.resources, json, satmotor_ros\n'
        'dist = importlib.metadata.distribution("satmotor_ros")\n'
        'print(json.dumps({"module": satmotor_ros.__file__,\n'
        '    "dist": str(dist.locate_file("")),\n'
        '    "entry": [e.value for e in dist.entry_points if e.name == "satmotor"],\n'
        '    "config": sorted(p.name for p in\n'
        '        importlib.resources.files("satmotor_ros.config").iterdir()\n'
        '        if p.name.endswith(".yaml"))}))\n'
    )
    proc = _run([interpreter, '-c', probe], sourced_install, tmp_path)
    assert proc.returncode == 0, proc.stderr
    found = json.loads(proc.stdout)
    prefix = colcon_build['prefix']
    assert Path(found['module']).is_relative_to(prefix), found
    assert Path(found['dist']).is_relative_to(prefix), found
    assert found['entry'] == ['satmotor_ros.cli:main'], found
    assert found['config'] == sorted(p.name for p in (REPO_ROOT / 'config').glob('*.yaml'))


def test_installed_satmotor_prints_help(sourced_install, tmp_path):
    """``ros2 run satmotor_ros satmotor --help`` equivalent exits 0 with a usage text."""
    proc = _run([_executable_path(PACKAGE, 'satmotor'), '--help'], sourced_install, tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert 'usage' in proc.stdout.lower()


def test_installed_satmotor_computes_the_oil_operating_point(sourced_install, tmp_path):
    """Oil, Q = 5 l/min, dp_i = 25 MPa gives about 133.2 rpm from the installed CLI."""
    argv = [_executable_path(PACKAGE, 'satmotor'), 'operating-point',
            '--liquid', 'oil', '--flow', '5', '--dp-i', '25', '--json']
    proc = _run(argv, sourced_install, tmp_path)
    assert proc.returncode == 0, proc.stderr
    result = json.loads(proc.stdout)
    assert result['speed_rpm'] == pytest.approx(133.2, abs=0.1)


def test_pip_wheel_ships_config_as_package_data(tmp_path):
    """A wheel (what ``pip install`` installs) carries config/*.yaml in satmotor_ros/config."""
    source = _copy_source(tmp_path / 'src')
    wheels = tmp_path / 'wheels'
    proc = subprocess.run(
        [sys.executable, '-m', 'pip', 'wheel', '--no-deps', '--wheel-dir', str(wheels),
         str(source)],
        cwd=tmp_path, capture_output=True, text=True, timeout=BUILD_TIMEOUT)
    assert proc.returncode == 0, f'pip wheel failed:\n{proc.stdout}\n{proc.stderr}'
    (wheel,) = wheels.glob(f'{PACKAGE}-*.whl')
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
    for yaml_file in (REPO_ROOT / 'config').glob('*.yaml'):
        assert f'{PACKAGE}/config/{yaml_file.name}' in names
    assert f'{PACKAGE}/py.typed' in names

# SPDX-License-Identifier: Apache-2.0
"""
The package builds with colcon and with pip, and runs the way ``ros2 run`` runs it.

colcon builds a copy of the source tree, so the checkout gets no ``build/`` or
``*.egg-info``, into colcon's default isolated layout (``<install>/satmotor_ros``).
The executable is then found as ``ros2 run`` finds it (ros2cli ``ros2run/api``:
``get_package_prefix`` from the ament index, then an executable file of that name under
``<prefix>/lib/<package>``), and run with the environment that sourcing the install's
setup script would give (its ``share/<package>/package.dsv`` hooks).

pip builds a wheel, which is installed into a clean venv (no system site packages, no ROS)
together with what setup.py declares, fetched from the package index (the versions pinned in
requirements.txt): the wheel alone must calibrate a bench table and replay a zstd-compressed
bag.  Every third-party module the package imports must be declared there and in package.xml.
"""

import ast
import csv
from email.parser import Parser
import importlib.metadata
import json
import os
from pathlib import Path
import re
import shutil
import signal
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
import zipfile

from ament_index_python.packages import get_package_prefix
import numpy as np
import pytest
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer
from rosbags.typesys import get_typestore, Stores
from satmotor_ros.cli import main

pytestmark = pytest.mark.slow

PACKAGE = 'satmotor_ros'
REPO_ROOT = Path(__file__).resolve().parent.parent
BUILD_TIMEOUT = 180.0  # a clean build takes a few seconds, [s]
RUN_TIMEOUT = 60.0  # one CLI call, [s]
INSTALL_TIMEOUT = 300.0  # the venv and its packages; about 15 s from pip's cache, [s]
BENCH_CSV = REPO_ROOT / 'test' / 'data' / 'bench_leak_water.csv'
# rosdep keys of the PyPI distributions that have one; the others are named in a comment of
# package.xml (rosdep has no key for them)
ROSDEP_KEYS = {'numpy': 'python3-numpy', 'scipy': 'python3-scipy', 'pyyaml': 'python3-yaml',
               'matplotlib': 'python3-matplotlib'}

# Top-level entries of a checkout that are not package source.
NOT_SOURCE = {'.git', '.venv', '.pytest_cache', '.hypothesis', '.mypy_cache', 'build', 'install',
              'log', 'out'}


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
    launch = sorted(p.name for p in (REPO_ROOT / 'launch').glob('*.launch.xml'))
    assert launch, 'launch/ holds no *.launch.xml'
    assert sorted(p.name for p in (prefix / 'share' / PACKAGE / 'launch').iterdir()) == launch
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


@pytest.fixture(scope='module')
def wheel(tmp_path_factory):
    """Build the package's wheel with ``pip wheel`` from a copy of the source; its path."""
    tmp = tmp_path_factory.mktemp('wheel')
    source = _copy_source(tmp / 'src')
    wheels = tmp / 'wheels'
    proc = subprocess.run(
        [sys.executable, '-m', 'pip', 'wheel', '--no-deps', '--wheel-dir', str(wheels),
         str(source)],
        cwd=tmp, capture_output=True, text=True, timeout=BUILD_TIMEOUT)
    assert proc.returncode == 0, f'pip wheel failed:\n{proc.stdout}\n{proc.stderr}'
    (built,) = wheels.glob(f'{PACKAGE}-*.whl')
    return built


def _clean_environment():
    """Return this process's environment without what would leak the checkout or ROS in."""
    env = dict(os.environ)
    for name in ('PYTHONPATH', 'PYTHONHOME', 'VIRTUAL_ENV', 'AMENT_PREFIX_PATH',
                 'COLCON_PREFIX_PATH', 'LD_LIBRARY_PATH'):
        env.pop(name, None)
    return env


@pytest.fixture(scope='module')
def clean_venv(wheel, tmp_path_factory):
    """
    Install the wheel and its declared dependencies, nothing else, into a new venv.

    Returns
    -------
    dict
        ``bin``: the venv's script directory; ``env``: the environment to run it with, [-]

    """
    venv = tmp_path_factory.mktemp('clean') / 'venv'
    env = _clean_environment()
    made = subprocess.run([sys.executable, '-m', 'venv', str(venv)], env=env,
                          capture_output=True, text=True, timeout=INSTALL_TIMEOUT)
    assert made.returncode == 0, made.stderr
    assert 'include-system-site-packages = false' in (venv / 'pyvenv.cfg').read_text()
    # the pins of requirements.txt as constraints: the index's versions the suite runs with
    install = [str(venv / 'bin' / 'python'), '-m', 'pip', 'install', '--no-compile',
               '--constraint', str(REPO_ROOT / 'requirements.txt'), str(wheel)]
    proc = subprocess.run(install, env=env, capture_output=True, text=True,
                          timeout=INSTALL_TIMEOUT)
    assert proc.returncode == 0, f'pip install failed:\n{proc.stdout}\n{proc.stderr}'
    env['PATH'] = os.pathsep.join([str(venv / 'bin'), env.get('PATH', '')])
    return {'bin': venv / 'bin', 'env': env}


def test_pip_wheel_ships_config_as_package_data(wheel):
    """A wheel (what ``pip install`` installs) carries config/*.yaml in satmotor_ros/config."""
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
    for yaml_file in (REPO_ROOT / 'config').glob('*.yaml'):
        assert f'{PACKAGE}/config/{yaml_file.name}' in names
    assert f'{PACKAGE}/py.typed' in names


def _runtime_nodes(tree):
    """
    Yield the nodes of a module that this interpreter runs.

    Left out: the body of ``if TYPE_CHECKING:`` (never run) and, of an ``if`` on
    ``sys.version_info``, the branch this Python version does not take.
    """
    todo = [tree]
    while todo:
        node = todo.pop()
        yield node
        test = ast.unparse(node.test) if isinstance(node, ast.If) else ''
        if 'TYPE_CHECKING' in test:
            todo.extend(node.orelse)
        elif test.startswith('sys.version_info'):
            todo.extend(node.body if eval(test, {'sys': sys}) else node.orelse)
        else:
            todo.extend(ast.iter_child_nodes(node))


def _third_party_imports():
    """Map each module imported at run time by satmotor_ros from outside it and the stdlib."""
    found = {}
    for path in sorted((REPO_ROOT / PACKAGE).rglob('*.py')):
        for node in _runtime_nodes(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                # `from backports import zstd` imports backports.zstd
                names = [f'{node.module}.{alias.name}' for alias in node.names]
            else:
                continue
            for name in names:
                top = name.partition('.')[0]
                if top != PACKAGE and top not in sys.stdlib_module_names:
                    found.setdefault(name, path.relative_to(REPO_ROOT))
    return found


def _normalised(name):
    """Return a distribution name as pip compares it (PEP 503)."""
    return re.sub(r'[-_.]+', '-', name).lower()


def _distribution_of(module):
    """Name the installed distribution whose files hold `module` (normalised), else None."""
    top = module.partition('.')[0]
    parts = module.split('.')
    for dist in importlib.metadata.packages_distributions().get(top, []):
        files = {Path(str(f)).with_suffix('').parts for f in importlib.metadata.files(dist)}
        # the deepest existing module or package of the dotted name
        for depth in range(len(parts), 0, -1):
            if tuple(parts[:depth]) in files or (*parts[:depth], '__init__') in files:
                return _normalised(dist)
    return None


def test_every_third_party_import_is_declared_in_setup_py_and_package_xml(wheel):
    """A module from a ROS package is an exec_depend; any other is a requirement of the wheel."""
    with zipfile.ZipFile(wheel) as archive:
        (metadata,) = [n for n in archive.namelist() if n.endswith('.dist-info/METADATA')]
        requires = Parser().parsestr(archive.read(metadata).decode()).get_all('Requires-Dist')
    declared = {_normalised(re.match(r'[A-Za-z0-9._-]+', r).group()) for r in requires or []}
    manifest = (REPO_ROOT / 'package.xml').read_text()
    exec_depends = {e.text for e in ElementTree.fromstring(manifest).iter('exec_depend')}
    problems = []
    for module, where in sorted(_third_party_imports().items()):
        if module.partition('.')[0] in exec_depends:
            continue  # a ROS package, found by rosdep and by colcon
        dist = _distribution_of(module)
        if dist is None or dist not in declared:
            problems.append(f'{where}: {module} (distribution {dist}) is in neither '
                            'setup.py install_requires nor package.xml exec_depend')
        elif dist in ROSDEP_KEYS and ROSDEP_KEYS[dist] not in exec_depends:
            problems.append(f'{where}: package.xml lacks <exec_depend>{ROSDEP_KEYS[dist]}')
        elif dist not in ROSDEP_KEYS and dist not in _normalised(manifest):
            problems.append(f'{where}: {dist} is not named in package.xml (the comment on '
                            'packages without a rosdep key)')
    assert not problems, '\n'.join(dict.fromkeys(problems))


def test_clean_venv_has_the_wheel_and_no_ros(clean_venv, tmp_path):
    """The venv's satmotor_ros is the installed wheel, rclpy is absent, and pip check passes."""
    probe = ('import importlib.util, json, sys, satmotor_ros\n'
             'print(json.dumps({"module": satmotor_ros.__file__, "prefix": sys.prefix,\n'
             '    "rclpy": importlib.util.find_spec("rclpy") is not None}))\n')
    proc = _run([clean_venv['bin'] / 'python', '-c', probe], clean_venv['env'], tmp_path)
    assert proc.returncode == 0, proc.stderr
    found = json.loads(proc.stdout)
    assert Path(found['module']).is_relative_to(found['prefix']), found
    assert not found['rclpy'], found
    check = _run([clean_venv['bin'] / 'python', '-m', 'pip', 'check'], clean_venv['env'],
                 tmp_path)
    assert check.returncode == 0, check.stdout + check.stderr


@pytest.mark.parametrize('argv', [['motor_model'], ['virtual_motor'], ['speed_controller'],
                                  ['motor_monitor'],
                                  ['satmotor', 'demo', '--quiet', '--out', 'demo']])
def test_wheel_alone_says_in_one_line_that_a_node_needs_ros(clean_venv, tmp_path, argv):
    """Issue 21: a node or the demo without ROS 2 is one line naming what to install."""
    proc = _run([clean_venv['bin'] / argv[0], *argv[1:]], clean_venv['env'], tmp_path)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert proc.stderr.count('\n') == 1 and 'pip install ros-kilted-rclpy' in proc.stderr, \
        proc.stderr
    assert not (tmp_path / 'demo').exists()


def test_wheel_alone_runs_satmotor_calibrate(clean_venv, tmp_path):
    """
    ``satmotor calibrate`` of the wheel finds the external leakage of a bench table.

    test/data/bench_leak_water.csv is the synthetic generator's table of
    ``generate(Plan(liquid='water'), Injection.realistic('external_leakage', 1, 'water'),
    seed=7)``, written as test_calibrate_cli writes it: 100 points, leakage through p_case.
    """
    argv = [clean_venv['bin'] / 'satmotor', 'calibrate', BENCH_CSV, '--liquid', 'water',
            '--out', tmp_path / 'out']
    proc = _run(argv, clean_venv['env'], tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    result = json.loads((tmp_path / 'out' / 'calibration.json').read_text())
    assert (result['effect'], result['regressor'], result['n_points']) == \
        ('external_leakage', 'p_case', 100)
    report = (tmp_path / 'out' / 'report.md').read_text()
    assert '(residuals.png)' in report
    assert (tmp_path / 'out' / 'residuals.png').read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'


def _zstd_bag(path, n):
    """
    Write the model's input topics, n messages each at 100 Hz, as a zstd-compressed bag.

    rosbags' writer compresses the whole storage file (``--compression-mode file``, as
    ``ros2 bag record`` does), leaving only metadata.yaml and a ``.db3.zstd`` file.
    """
    typestore = get_typestore(Stores.ROS2_KILTED)
    types = typestore.types
    rng = np.random.default_rng(3)
    t = 1_700_000_000_000_000_000 + np.arange(n, dtype=np.int64) * 10_000_000
    writer = Writer(path, version=9, storage_plugin=StoragePlugin.SQLITE3)
    writer.set_compression(CompressionMode.FILE, CompressionFormat.ZSTD)
    with writer:
        flow = writer.add_connection('/flow_command', 'std_msgs/msg/Float64',
                                     typestore=typestore)
        ports = [writer.add_connection(name, 'sensor_msgs/msg/FluidPressure',
                                       typestore=typestore)
                 for name in ('/inlet_pressure', '/outlet_pressure')]
        for k, stamp in enumerate(t.tolist()):
            header = types['std_msgs/msg/Header'](
                stamp=types['builtin_interfaces/msg/Time'](sec=stamp // 10**9,
                                                           nanosec=stamp % 10**9),
                frame_id='')
            for port, pressure in zip(ports, (rng.uniform(5e6, 25e6), rng.uniform(2e5, 1e6))):
                message = types['sensor_msgs/msg/FluidPressure'](
                    header=header, fluid_pressure=pressure, variance=0.0)
                writer.write(port, stamp, typestore.serialize_cdr(
                    message, 'sensor_msgs/msg/FluidPressure'))
            command = types['std_msgs/msg/Float64'](data=rng.uniform(5, 40) / 60000.0)
            writer.write(flow, stamp + 1_000_000 + k % 2, typestore.serialize_cdr(
                command, 'std_msgs/msg/Float64'))
    assert sorted(p.suffix for p in path.iterdir()) == ['.yaml', '.zstd']


def _rows(path):
    with open(path, newline='') as stream:
        return list(csv.DictReader(stream))


def test_wheel_alone_replays_a_zstd_compressed_bag(clean_venv, tmp_path, capsys):
    """``satmotor replay`` of the wheel reads a file-compressed bag as the source tree does."""
    _zstd_bag(tmp_path / 'bag', 200)
    argv = [clean_venv['bin'] / 'satmotor', 'replay', tmp_path / 'bag', '--liquid', 'oil',
            '--no-plot', '--out', tmp_path / 'wheel.csv']
    proc = _run(argv, clean_venv['env'], tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert '200 driving messages, 200 predictions' in proc.stdout
    assert main(['replay', str(tmp_path / 'bag'), '--liquid', 'oil', '--no-plot',
                 '--out', str(tmp_path / 'source.csv')]) == 0
    capsys.readouterr()
    wheel_rows = _rows(tmp_path / 'wheel.csv')
    assert len(wheel_rows) == 200
    assert all(float(r['speed [rpm]']) > 0 for r in wheel_rows)
    assert wheel_rows == _rows(tmp_path / 'source.csv')

# SPDX-License-Identifier: Apache-2.0
"""
The XML launch files, checked statically (ros2 launch is not installed here).

Each file must parse as XML in the ROS 2 launch frontend's vocabulary (elements and their
attributes as launch and launch_ros read them), start only this package's console scripts,
set only parameters the node declares, read only parameter files the package installs, and
define every ``$(var ...)`` it uses with an ``<arg>``.
"""

from pathlib import Path
import re
import xml.etree.ElementTree as ElementTree

import pytest
from satmotor_ros.nodes import motor_model, motor_monitor, speed_controller, virtual_motor

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = 'satmotor_ros'
LAUNCH_FILES = sorted((ROOT / 'launch').glob('*.launch.xml'))

SCHEMA = {  # element -> attributes, as the ROS 2 XML launch frontend knows them
    'launch': {'version'},
    'arg': {'name', 'default', 'description'},
    'let': {'name', 'value'},
    'group': {'scoped', 'forwarding', 'if', 'unless'},
    'push_ros_namespace': {'namespace'},
    'node': {'pkg', 'exec', 'name', 'namespace', 'output', 'args', 'ros_args', 'respawn',
             'respawn_delay', 'launch-prefix', 'if', 'unless', 'exec_name'},
    'param': {'name', 'value', 'from', 'sep'},
    'remap': {'from', 'to'},
    'set_remap': {'from', 'to'},
    'set_parameter': {'name', 'value'},
    'include': {'file', 'if', 'unless'},
    'env': {'name', 'value'},
    'set_env': {'name', 'value'},
}
CHILDREN = {'launch': {'arg', 'let', 'group', 'node', 'include', 'set_env', 'set_remap',
                       'set_parameter', 'push_ros_namespace'},
            'group': {'arg', 'let', 'group', 'node', 'include', 'set_env', 'set_remap',
                      'set_parameter', 'push_ros_namespace'},
            'node': {'param', 'remap', 'env'}, 'include': {'arg'}}
SUBSTITUTION = re.compile(r'\$\((\S+)(?: ([^)]*))?\)')
NODE_PARAMETERS = {
    'motor_model': {s.name for s in motor_model.PARAMETERS},
    'virtual_motor': {s.name for s in virtual_motor.all_parameters()},
    'speed_controller': {s.name for s in speed_controller.PARAMETERS},
    'motor_monitor': {s.name for s in motor_monitor.PARAMETERS},
}
"""What each executable declares; use_sim_time every node has."""


def _console_scripts():
    text = (ROOT / 'setup.py').read_text(encoding='utf-8')
    return set(re.findall(r"'(\w+) = [\w.]+:\w+'", text))


def _installed_path(text):
    """Map ``$(find-pkg-share satmotor_ros)/config/x.yaml`` to the source file installed there."""
    prefix = f'$(find-pkg-share {PACKAGE})/'
    assert text.startswith(prefix), text
    relative = text[len(prefix):]
    setup = (ROOT / 'setup.py').read_text(encoding='utf-8')
    folder = relative.split('/')[0]
    assert f"'/{folder}'" in setup, f'setup.py installs nothing to share/{PACKAGE}/{folder}'
    return ROOT / relative


@pytest.fixture(params=LAUNCH_FILES, ids=[p.name for p in LAUNCH_FILES])
def launch(request):
    return request.param, ElementTree.parse(request.param).getroot()


def test_the_bench_and_the_model_alone_are_there():
    assert {p.name for p in LAUNCH_FILES} == {'motor_bench.launch.xml', 'motor_model.launch.xml'}


def test_elements_and_attributes_are_the_launch_frontends(launch):
    path, root = launch
    assert root.tag == 'launch'

    def walk(element):
        assert element.tag in SCHEMA, f'{path.name}: <{element.tag}> is no launch element'
        unknown = set(element.attrib) - SCHEMA[element.tag]
        assert not unknown, f'{path.name}: <{element.tag}> has no attribute {unknown}'
        for child in element:
            assert child.tag in CHILDREN.get(element.tag, set()), \
                f'{path.name}: <{child.tag}> inside <{element.tag}>'
            walk(child)
    walk(root)
    for arg in root.iter('arg'):
        assert arg.get('name') and arg.get('description'), arg.attrib
    for node in root.iter('node'):
        assert node.get('pkg') and node.get('exec'), node.attrib
    for param in root.iter('param'):
        assert (param.get('name') is None) == (param.get('value') is None) != \
            (param.get('from') is None), param.attrib


def test_namespace_liquid_and_motor_file_are_arguments(launch):
    _, root = launch
    args = {arg.get('name') for arg in root.iter('arg')}
    assert {'namespace', 'liquid', 'motor_file'} <= args
    for node in root.iter('node'):
        assert node.get('namespace') == '$(var namespace)'
        values = {p.get('name'): p.get('value') for p in node.iter('param') if p.get('name')}
        assert values['liquid'] == '$(var liquid)'
        assert values['motor_file'] == '$(var motor_file)'


def test_every_variable_has_an_arg_and_every_arg_is_used(launch):
    path, root = launch
    args = {arg.get('name') for arg in root.iter('arg')}
    used = set()
    for element in root.iter():
        for value in element.attrib.values():
            for kind, operand in SUBSTITUTION.findall(value):
                assert kind in ('var', 'find-pkg-share'), f'{path.name}: $({kind} ...)'
                if kind == 'var':
                    used.add(operand)
                else:
                    assert operand == PACKAGE, value
    assert used <= args, f'{path.name}: $(var) without an <arg>: {used - args}'
    assert args <= used, f'{path.name}: <arg> never used: {args - used}'


def test_every_executable_is_a_console_script_and_every_param_is_declared(launch):
    path, root = launch
    scripts = _console_scripts()
    for node in root.iter('node'):
        assert node.get('pkg') == PACKAGE
        assert node.get('exec') in scripts, f'{path.name}: no console script {node.get("exec")}'
        declared = NODE_PARAMETERS[node.get('exec')] | {'use_sim_time'}
        for param in node.iter('param'):
            if param.get('name') is not None:
                assert param.get('name') in declared, (path.name, param.attrib)


def test_every_parameter_file_exists_and_is_installed(launch):
    path, root = launch
    files = [p.get('from') for p in root.iter('param') if p.get('from')]
    files += [a.get('default') for a in root.iter('arg')
              if a.get('name') == 'motor_file' and a.get('default')]
    assert files
    for text in files:
        source = _installed_path(text)
        assert source.is_file(), f'{path.name}: {text} is {source}, which does not exist'
        assert source.suffix == '.yaml'


def test_make_run_deletes_nothing_the_demo_did_not_write():
    """Issue 21: `make run` left out/demo to the demo's own rule (replace only its own)."""
    text = (ROOT / 'Makefile').read_text(encoding='utf-8')
    recipe = re.search(r'^run:.*\n((?:\t.*\n)+)', text, re.MULTILINE)
    assert recipe, 'no run target'
    lines = recipe.group(1).splitlines()
    assert not [line for line in lines if re.search(r'\brm\b', line)], lines
    assert any('satmotor demo --out out/demo' in line for line in lines), lines


def test_every_parameter_file_addresses_the_node_that_reads_it(launch):
    import yaml
    path, root = launch
    for node in root.iter('node'):
        for param in node.iter('param'):
            if param.get('from'):
                keys = yaml.safe_load(_installed_path(param.get('from')).read_text('utf-8'))
                assert f'/**/{node.get("name")}' in keys, (path.name, param.get('from'))


def test_the_model_on_a_real_motor_has_no_default_liquid():
    # ros2 launch refuses a required argument left out: the rig's liquid is never guessed.
    root = ElementTree.parse(ROOT / 'launch' / 'motor_model.launch.xml').getroot()
    (liquid,) = [arg for arg in root.iter('arg') if arg.get('name') == 'liquid']
    assert liquid.get('default') is None

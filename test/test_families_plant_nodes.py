# SPDX-License-Identifier: Apache-2.0
"""Every model family in the plant and the nodes, through the same MotorOptions."""

from node_harness import unique_namespace
import pytest
from rclpy.parameter import Parameter
from satmotor_ros.model import MotorModel
from satmotor_ros.model.families import FAMILY_NAMES
from satmotor_ros.model.units import CM3_PER_REV, LPM, MPA
from satmotor_ros.nodes.motor_model import MotorModelNode
from satmotor_ros.options import MotorOptions, OptionError
from satmotor_ros.plant import ConstantLoad, Plant
from std_msgs.msg import Float64

PASZOTA_YAML = """\
motor: F11-5 (example)
family: paszota
geometry:
  displacement: 0.30 in^3/rev
valid_range:
  dp_max: 21 MPa
  speed_max: 3000 rpm
coefficient_sets:
  oil:
    liquid: {kinematic_viscosity: 32 cSt, density: 870 kg/m^3, bulk_modulus: 1.6 GPa}
    coefficients: {k_g: 0.03, a_pv: 0.9, a_nv: 0.2, a_vv: -0.6, p_n: 21 MPa, n_t: 3000 rpm,
                   c_t: 20.0, c_l: 5.0}
"""


@pytest.mark.parametrize('family', FAMILY_NAMES)
@pytest.mark.parametrize('liquid', ['oil', 'water'])
def test_a_virtual_motor_of_every_family_settles_at_its_models_speed(family, liquid):
    model = MotorOptions(liquid=liquid, family=family).build_model()
    assert model.family.name == family
    plant = Plant(model, load=ConstantLoad(60.0))
    flow = 20 * LPM
    plant.run(4000, flow)
    for _ in range(40):
        before = plant.state
        plant.run(500, flow)
        if abs(plant.state.speed - before.speed) <= 1e-10 * before.speed:
            break
    state = plant.state
    dp = state.inlet_pressure - state.outlet_pressure
    assert plant.flows.relief == 0.0
    assert state.speed == pytest.approx(model.speed_point(flow, dp).speed, rel=1e-7)
    assert plant.chamber_pressure_drop == pytest.approx(model.speed_point(flow, dp).dp_i,
                                                        rel=1e-7)


def test_motor_options_build_a_motor_of_a_family_or_a_displacement():
    f11 = MotorOptions(family='paszota', displacement=0.30 * 16.387064 * CM3_PER_REV)
    model = f11.build_model()
    assert model.family.name == 'paszota'
    assert model.geometry.displacement == pytest.approx(4.9161 * CM3_PER_REV, rel=1e-4)
    assert MotorOptions(displacement=1e-6).build_model().family.name == 'sliwinski2017'
    with pytest.raises(OptionError, match="family = 'wilson'"):
        MotorOptions(family='wilson')
    with pytest.raises(OptionError, match='not both'):
        MotorOptions(motor_file='x.yaml', displacement=1e-6)
    with pytest.raises(OptionError, match='is a sliwinski2017 motor'):
        MotorOptions(motor_file=str(_packaged()), family='paszota').build_model()


def test_motor_model_node_predicts_a_paszota_motor_from_its_yaml(harness, tmp_path):
    path = tmp_path / 'f11_5.yaml'
    path.write_text(PASZOTA_YAML, encoding='utf-8')
    ns = unique_namespace('paszota')
    node = MotorModelNode(context=harness.context, namespace=ns,
                          parameter_overrides=[Parameter('motor_file', value=str(path))])
    harness.executor.add_node(node)
    try:
        motor = harness.motor(ns)
        harness.wait_connected(motor)
        for _ in range(3):
            motor.inputs(p_in=15 * MPA, p_out=0.5 * MPA)
            harness.spin_for(0.03)
        motor.flow.publish(Float64(data=12 * LPM))
        assert harness.spin_until(lambda: motor.predicted and motor.losses['total'], 5.0)
        model = MotorOptions(motor_file=str(path)).build_model()
        expected = model.speed_point(12 * LPM, 14.5 * MPA)
        assert model.family.name == 'paszota' and expected.status == 0
        assert motor.predicted[0].velocity[0] == pytest.approx(expected.speed, rel=1e-12)
        assert motor.losses['total'][0].data == pytest.approx(expected.total, rel=1e-12)
        assert motor.losses['flat_clearance'][0].data == 0.0  # eq. (29) shows no sources
    finally:
        harness.executor.remove_node(node)
        node.destroy_node()


def test_node_family_and_displacement_parameters_rebuild_or_refuse(harness):
    node = MotorModelNode(context=harness.context, namespace=unique_namespace('fam'))
    try:
        (bad,) = node.set_parameters([Parameter('family', value='wilson')])
        assert not bad.successful and 'use one of' in bad.reason
        (ok,) = node.set_parameters([Parameter('family', value='balawender')])
        assert ok.successful and node._model.family.name == 'balawender'
        (ok,) = node.set_parameters([Parameter('displacement', value=1e-6)])
        assert ok.successful and node._model.geometry.displacement == 1e-6
    finally:
        node.destroy_node()


def _packaged():
    from satmotor_ros.model.io.config import default_config_path
    return default_config_path()


def test_every_family_builds_from_the_packaged_liquids():
    for family in FAMILY_NAMES:
        for liquid in ('oil', 'water'):
            model = MotorModel.for_displacement(None, family, liquid)
            assert model.speed_point(10 * LPM, 10 * MPA).status & 0xF8 == 0


@pytest.mark.parametrize('family', ['balawender', 'paszota'])
def test_effects_of_a_coefficient_set_work_in_every_family(family, tmp_path):
    from satmotor_ros.model.io.config import motor_from_mapping
    doc = {'motor': 'x', 'family': family, 'geometry': {'displacement': '10 cm^3/rev'},
           'valid_range': {'dp_max': '25 MPa', 'speed_max': '2000 rpm'},
           'coefficient_sets': {'oil': {
               'liquid': {'kinematic_viscosity': '40 cSt', 'density': 873,
                          'bulk_modulus': '1.6 GPa'},
               'coefficients': {'external_leakage': 1e-12},
               'effects': {
                   'external_leakage': {'regressor': 'p_case', 'coefficient': 1e-12},
                   'viscosity_temperature': {'regressor': 'temperature', 'coefficient': 3.68,
                                             'law': 'walther', 'reference_temperature': 40.0,
                                             'reference_viscosity': 40e-6}}}}}
    model = MotorModel.from_spec(motor_from_mapping(doc))
    assert model.family.name == family and set(model.channels) == {'p_case', 'temperature'}
    cool = model.absorbency_point(1000 * 0.10471975511965977, 10 * MPA,
                                  channels={'p_case': 2e5, 'temperature': 40.0})
    hot = model.absorbency_point(1000 * 0.10471975511965977, 10 * MPA,
                                 channels={'p_case': 2e5, 'temperature': 70.0})
    assert cool.status & 0xF8 == 0 and hot.status & 0xF8 == 0
    assert cool.external == pytest.approx(1e-12 * 2e5)
    assert hot.total > cool.total  # thinner oil leaks more

"""Packaging for satmotor_ros (ament_python: colcon and pip use the same file)."""

from glob import glob
import os

from setuptools import find_packages
from setuptools import setup

package_name = 'satmotor_ros'

# The canonical coefficient sets and parameter files live in the top-level config/ directory.
# colcon installs them to share/<pkg>/config (data_files).  For pip installs the same files
# are shipped as package data of a virtual subpackage `satmotor_ros.config` whose directory is
# mapped onto config/ (package_dir), so importlib.resources.files('satmotor_ros.config')
# finds them.
config_files = sorted(glob(os.path.join('config', '*.yaml')))
# The XML launch files go to share/<pkg>/launch, where `ros2 launch satmotor_ros X` finds them.
launch_files = sorted(glob(os.path.join('launch', '*.launch.xml')))

setup(
    name=package_name,
    version='0.1.0',
    # include= rather than exclude=['test']: it also keeps bench/ and config/ (should it ever
    # get an __init__.py) from being installed as top-level packages.
    packages=[
        *find_packages(include=[package_name, package_name + '.*']),
        package_name + '.config',
    ],
    package_dir={package_name + '.config': 'config'},
    package_data={
        package_name: ['py.typed'],
        package_name + '.config': ['*.yaml'],
    },
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', config_files),
        ('share/' + package_name + '/launch', launch_files),
    ],
    python_requires='>=3.10',
    # Every third-party module satmotor_ros imports (test_package_build checks the list against
    # the imports and installs the wheel with only these into a clean venv).  rclpy and the
    # message packages are not on PyPI as such: they come from the ROS 2 installation
    # (package.xml), and only the nodes and `satmotor demo` import them.
    install_requires=[
        'numpy',
        'scipy',  # identify/: least squares, t and F distributions
        'PyYAML',
        'matplotlib',  # plots of calibrate, replay, characteristics, demo
        'rosbags',  # bag reading and writing (sqlite3 and MCAP storage, metadata.yaml)
        'apsw',  # rosbags reads .db3 files through it; bags/storage.py catches its errors
        'mcap',  # MCAP chunks with CRCs (writing), MCAP files rosbags cannot open (reading)
        # zstd FILE and MESSAGE compressed bags; the stdlib has compression.zstd from Python
        # 3.14 on, which backports.zstd backports
        'backports.zstd; python_version < "3.14"',
        # `satmotor fleet`: its tasks on a local or an existing Dask cluster
        'dask',
        'distributed',
    ],
    zip_safe=False,
    maintainer='satmotor_ros developers',
    maintainer_email='satmotor_ros@example.com',
    description='Volumetric losses and shaft speed of a hydraulic satellite motor, '
                'a virtual motor plant, calibration tools and rclpy nodes.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'satmotor = satmotor_ros.cli:main',
            'motor_model = satmotor_ros.nodes.launch:motor_model',
            'virtual_motor = satmotor_ros.nodes.launch:virtual_motor',
            'speed_controller = satmotor_ros.nodes.launch:speed_controller',
            'motor_monitor = satmotor_ros.nodes.launch:motor_monitor',
        ],
    },
)

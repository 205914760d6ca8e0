# SPDX-License-Identifier: Apache-2.0
"""The ``satmotor`` command line: hydraulic units in, SI inside."""

from satmotor_ros.cli.main import main

__all__ = ['main']

# SPDX-License-Identifier: Apache-2.0
"""ROS 2 nodes and a volumetric-loss model for the hydraulic satellite motor."""

__version__ = '0.1.0'

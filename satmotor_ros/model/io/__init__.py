# SPDX-License-Identifier: Apache-2.0
"""Motor files in and out: a motor YAML read into a :class:`~.config.MotorSpec`."""

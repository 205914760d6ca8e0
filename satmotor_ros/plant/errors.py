# SPDX-License-Identifier: Apache-2.0
"""Exceptions of the plant layer."""


class PlantError(ValueError):
    """A plant parameter or input is invalid; the message names the field and the value."""

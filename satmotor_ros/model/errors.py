# SPDX-License-Identifier: Apache-2.0
"""Exceptions of the model layer."""


class ModelError(ValueError):
    """Base of every error the model raises."""


class ConfigError(ModelError):
    """A coefficient set, geometry or liquid is malformed; the message names the key."""


class InvalidInputError(ModelError):
    """An operating point cannot be evaluated; the message names the argument and value."""


class UnitError(ModelError):
    """A quantity carries a unit that is unknown or of the wrong kind."""

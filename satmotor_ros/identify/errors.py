# SPDX-License-Identifier: Apache-2.0
"""Exceptions of the identification layer."""


class IdentificationError(ValueError):
    """The data cannot support the requested fit; the message says why."""


class DataError(IdentificationError):
    """A bench table or recording is unusable; the message names the column or topic."""

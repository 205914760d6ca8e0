# SPDX-License-Identifier: Apache-2.0
"""Exceptions of the bag layer."""


class BagError(ValueError):
    """A bag cannot be read or written as asked; the one-line message says what and why."""

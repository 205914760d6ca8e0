# SPDX-License-Identifier: Apache-2.0
"""The one error of the fleet layer."""


class FleetError(ValueError):
    """A fleet that cannot be run as asked: one line naming the field and the value."""


__all__ = ['FleetError']

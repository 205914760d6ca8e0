# SPDX-License-Identifier: Apache-2.0
"""
Fleets: every recording of every motor, as tasks on Dask, and the fleet's view.

:mod:`.config` reads fleet.yaml, :mod:`.discover` finds and orders the recordings,
:mod:`.resume` knows what is done, :mod:`.tasks` is what a worker runs (through the
functions of ``satmotor calibrate`` and ``validate``, and :mod:`.health`, the one health
step), :mod:`.engine` plans and runs them on a cluster, :mod:`.summary` and :mod:`.report`
write fleet.json, fleet.md and the plots. It sits at the command line's layer.
"""

from satmotor_ros.fleet.errors import FleetError
from satmotor_ros.fleet.run import Outcome, run_fleet
from satmotor_ros.fleet.summary import LIMIT

__all__ = ['FleetError', 'LIMIT', 'Outcome', 'run_fleet']

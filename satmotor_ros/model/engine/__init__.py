# SPDX-License-Identifier: Apache-2.0
"""
The evaluation engine: screening, statuses, solves, the quadrant rule and the effects.

It evaluates the equations a family composes (:mod:`satmotor_ros.model.families`) at one
point on Python floats (:mod:`.point`, the rules of :mod:`.screening` inlined) and over
arrays (:mod:`.inverse`, :mod:`.forward`, :mod:`.batch`); :mod:`.quadrants` turns every
signed point into one at magnitudes, :mod:`.conditioned` and :mod:`.valves` add the effects.
"""

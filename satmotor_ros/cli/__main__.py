# SPDX-License-Identifier: Apache-2.0
"""Allow ``python -m satmotor_ros.cli``."""

import sys

from satmotor_ros.cli.main import main

sys.exit(main())

"""``python -m landing_gear_sim``: the same as ``landing-gear-sim``."""

import sys

from landing_gear_sim.cli import main

sys.exit(main())

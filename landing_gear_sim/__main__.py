"""``python -m landing_gear_sim``: the same as ``landing-gear-sim``."""

import sys

from .cli import main

sys.exit(main())

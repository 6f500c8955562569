"""Figures, tables and HTML pages. They take computed results and never simulate or fit.

matplotlib runs on the non-interactive Agg backend (selected here, before any figure
module imports pyplot): figures go to PNG files.
"""

import matplotlib

matplotlib.use("Agg")

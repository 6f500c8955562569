"""Figures, tables and HTML pages. They take computed results and never simulate or fit.

Only the modules that draw import matplotlib (on its Agg backend: figures go to PNG files,
see :mod:`~landing_gear_sim.report.figures`): a command that prints a table or a summary
and draws nothing does not wait for it.
"""

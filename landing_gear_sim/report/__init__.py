"""Figures, tables and HTML pages. They take computed results and never simulate or fit.

matplotlib runs on the non-interactive Agg backend: figures go to PNG files.
"""

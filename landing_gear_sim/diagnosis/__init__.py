"""Why model and rig disagree: residual analysis, the catalogue of candidate elements,
and the diagnosis that scores them, extends the model and measures the gain."""

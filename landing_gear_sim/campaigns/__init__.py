"""Many campaigns at once: a Dask engine (:mod:`.engine`) and a rig's history
(:mod:`.history`)."""

"""The QGIS desktop face: the GCP dock, its map tool and photo viewer, styled result layers.

Nothing here is imported when the plugin loads or under qgis_process; plugin.initGui and the
Processing post-processing hook import these modules when they are needed.
"""

"""Automatic ground control from a reference orthophoto and DSM (issue 16).

No hand-picked GCP: a provisional orthophoto of the aligned block (``provisional``) is matched to the reference
orthophoto at a common ground resolution (``matching``: RootSIFT, ratio test, RANSAC similarity, then an affine
per tile); each match is tied back to the photos through the model and the other photos (``candidates``), takes
its height from the reference DSM, and becomes a GCP candidate (role ``auto``) with a sigma from the reference's
resolution and the match quality; the usual GCP-constrained adjustment with its outlier rejection then
georeferences the block (``stage.autocontrol_workspace``).  Without a prior (no GPS, no placement) the rotation
and scale are searched first (``matching.coarse_search``).  Another epoch (photos of another year or season) is
registered to an earlier, georeferenced workspace's orthomosaic and DSM by ``epochs.register_epoch``.
"""

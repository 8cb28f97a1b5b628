"""Find targets: surveyed ground targets found on the photos of an aligned block (issue 34).

``detect`` finds candidate marks on each photo (cross, checkerboard, circle, ArUco/AprilTag) at sub-pixel;
``tie`` ties them across photos by triangulation in the model frame; ``constellation`` matches the
triangulated marks to the surveyed coordinates (a similarity from triplets, scale and mirror searched);
``clicks`` and ``prior`` (EXIF GPS) narrow it when the user has them; ``stage.find_targets`` is the one entry
point (options in ``options``).
"""

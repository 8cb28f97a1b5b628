"""The orthophoto room: true orthophotos per image, the orthomosaic, and single-image orthorectification on an
existing DSM.

Pure Python + numpy + OpenCV + GDAL: no qgis, no Qt (docs/architecture.md).

How a cell of an orthophoto gets its value
------------------------------------------
Every output cell (a north-up grid in the working CRS) takes its height from the DSM (bilinear), goes
through the full camera model (pose, intrinsics, lens distortion: :class:`core.geometry.camera.Intrinsics`) into
the image, and is sampled there (bilinear by default, cubic or nearest on request; 8/16-bit, float, any
number of bands, kept as they are).  A cell is *nodata* (alpha 0) when it falls outside the image, in a
masked area (``<workspace>/masks/<image>.png``, white = use), where the DSM has no height, or when it is
hidden from that camera by higher surface.

Occlusion: radial sweep from the nadir point
--------------------------------------------
Seen from a camera at height H over the nadir point N, a surface point at horizontal distance r and height z
has the "tangent" t = r / (H - z).  Along every radial line from N, a point is visible exactly when its t is
not below the largest t of the surface closer to N (Habib et al. 2007, angle-based true orthophotos).  Per
image the DSM is resampled on a polar grid around N (bins of half a DSM cell), the running maximum of t is
taken along each ray (``np.maximum.accumulate``), and a cell is hidden when its height lies more than a small
tolerance below the sight line over that maximum.  The polar table is built once per image from the DSM of
its footprint and cached on disk, so a tile needs only table look-ups: no z-buffer splatting artefacts, no
per-cell ray marching, and memory per image independent of the output area.

Orthomosaic
-----------
1. A *planning grid* (a few GSD per cell, its size fixed in ground units, independent of the output
   resolution) holds for every image its validity and a cost (squared distance from the principal point +
   squared tangent of the viewing angle: "closest to nadir"); each planning cell takes the cheapest valid
   image.
2. Seamlines avoid relief: objects standing above their surroundings (buildings, trees: a morphological
   top-hat of the DSM) are given whole to one image that sees all of them, so no seam cuts a roof or a crown
   (where a seam would show any DSM error as a step).
3. Exposure: one gain per image from the mean brightness of the overlaps (least squares, as OpenCV's gain
   compensator).
4. Tiles (512 cells, memory bounded by one tile and the caches): each image's label region is feathered
   (a linear ramp across the seam), or blended with a Laplacian pyramid (multi-band), or cut hard; cells whose
   image is occluded there at full resolution are filled from the best image that sees them.
5. Tiles stream into a tiled GeoTIFF that becomes a Cloud-Optimized GeoTIFF with overviews; optional per-image
   true orthophotos (COG) and a GeoPackage layer of which image each part of the mosaic comes from.

Outputs are written to a temporary name and renamed when complete (``core.common.files.atomic_output``).

Modules (each one concern; import a name from the module that defines it)
--------------------------------------------------------------------------
options (OrthoOptions, SingleImageOptions, OrthoError), cameras (OrthoCamera, IMAGES_FILTER), surface (the DSM
in the working CRS, gap filling), visibility (footprints, polar occlusion tables), pixels (image windows,
masks, the cache, remap), sampling (where ground points fall in a camera, and its values there), grid (tiles
and cells), writer (the COG writer), block (the set-up shared by mosaic and single images, per-image orthophotos), planning (the
mosaic's plan: which image each cell takes, seams moved by minimum cut, exposure), seamlines (the seamlines
GeoPackage read back with the user's edits), blend (multi-band pyramids), tiles (one mosaic tile), mosaic (build_orthomosaic),
stage (the workspace stage), orientation (orientation files), imagecontrol (one image's run record and the
ground control observed in it), planar (planar rectification), single (orthorectify_image).
"""

"""DEM co-registration (issue 32 item 4): the block's DSM, or its sparse points, against a reference DEM.

Nuth & Kääb (2011) with a tilt and an optional dome, solved jointly and iterated.  For a DEM whose coordinates
are off by ``s`` (the thing that is at ``p + s`` in the reference is at ``p`` in the DEM) and whose heights are
off by ``dz`` and a smooth surface, the elevation difference to the reference is, to first order,

    dh(q) = R(q) - D(q) = tan(slope) * |s| * cos(direction(s) - aspect) + dz + plane(q) + dome(q)
                        = -dR/dx * sx - dR/dy * sy + dz + plane(q) + dome(q)

(aspect: the direction of steepest descent, clockwise from north).  Nuth & Kääb divide by tan(slope) and fit the
cosine to medians of aspect bins, then take the median of dh as the vertical bias; the same relation is solved here
in its multiplied form, by least squares over every stable cell together with the plane (and dome) terms, so that a
tilt or a dome does not leak into the shift and flat cells (tan(slope) -> 0) need no special case.  Each iteration
resamples the DEM at the shifted positions (bilinear), recomputes dh, keeps the stable cells (``stable_mask``, not
too steep, within ``OUTLIER_NMAD`` spreads (as an NMAD) of the centre of the residuals' shortest half: new
buildings, forest, landslides drop out, up to nearly half of the overlap, where a median would follow them) and
adds the increment; it stops when the shift changes by less than ``tolerance`` cells and the model by less than
a twentieth of the residual NMAD.  The iterations start from the whole-cell shift (within ``SEARCH_CELLS``) whose
differences have the narrowest shortest half, and fit the shift and dz alone before the tilt: while the shift is
large, changed areas are not told from the terrain by their residuals and a tilt would take up a forest on one
side.  The vertical bias is finally set to the median of the stable residuals.  Where the terrain cannot fix the
shift (flat, or the surfaces too different), dx = dy = 0 is held, ``horizontal_determined`` is False and a
message says why.

Conventions (metres, the reference's horizontal CRS):

- ``CoregResult.shift = (dx, dy, dz)``: add (dx, dy) to the DEM's coordinates and dz to its heights;
- ``CoregResult.correction(x, y)``: the height to add at reference position (x, y): dz + a (x - x0) + b (y - y0)
  (+ cxx (x - x0)^2 + cxy (x - x0)(y - y0) + cyy (y - y0)^2 with ``dome``); (x0, y0) = ``origin``, the centroid of
  the compared cells;
- ``CoregResult.apply(xyz)``: the corrected points (x + dx, y + dy, z + correction(x + dx, y + dy)).

Both rasters are compared on one grid at the coarser cell size (aligned on the reference's grid; a finer raster
is averaged onto it by GDAL, reprojected there if its CRS differs), float32, at most ``MAX_GRID_CELLS`` cells (a
coarser multiple beyond that), and at most ``MAX_FIT_CELLS`` cells (a fixed random subset) enter the fit: peak
memory is a few copies of the coarse grid, never of the full-resolution DSM (``coregister_rasters`` warps it from
the file).

Entry points: :func:`coregister_dems` (two :class:`HeightGrid`: arrays + GDAL geotransforms),
:func:`coregister_rasters` (two files: CRS, linear and vertical units, nodata), :func:`coregister_points` (the
sparse cloud against a reference DEM, sampled bilinearly; :func:`coregister_points_file` reads the reference over
the points only, reprojected into the points' CRS: :func:`reference_window`), :func:`control_points_from_coregistration` (well-distributed pseudo control
points on flat, stable, well-measured cells, for the adjustment).  Bad input is a :class:`CoregError` naming the
raster.

Why not xdem (or codem, PDAL): xdem needs rasterio, pyproj, geopandas, pandas and xarray (wheels with their own
GDAL and PROJ beside QGIS's), which QGIS's Python on Windows and macOS does not have; its NuthKaab fits the shift
alone, so a tilt of the block pulls it off (benchmarks/coregister.py: 22 m on the tilted synthetic pair where this
module finds 0.01 m; without tilt both are within 0.03 cell).  tests/test_coregister.py compares with xdem where it
is installed.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from typing import Callable, List, Optional, Sequence, Tuple

import numpy as np

from ..common.errors import ArchaeoOrthoError
from ..common.progress import NullProgress, Progress, check_cancel
from ..io.raster import RasterError, RasterFile, bilinear, check_heights

OUTLIER_NMAD = 3.0  # residuals beyond this many spreads of the shortest half's centre are not stable terrain
MAX_SLOPE_DEG = 70.0  # steeper cells (cliffs, walls) are left out of the fit
MIN_CELLS = 100  # stable cells needed for a fit
MAX_GRID_CELLS = 4_000_000  # the comparison grid is coarsened beyond this (16 MiB per float32 copy)
MAX_FIT_CELLS = 500_000  # a fixed random subset of the compared cells enters the fit (as xdem's default)
MAX_STEP_CELLS = 4.0  # the horizontal increment of one iteration is limited to this many cells
UNDETERMINED_CELLS = 0.25  # the shift's standard error (cells) above which the terrain is too flat for it
FLAT_NMADS = 1.0  # ... or when a one-cell shift changes the heights (RMS) by less than this many residual NMADs
DEM_MARGIN_CELLS = 8  # the DEM is kept this far around the overlap, for shifted samples
SEARCH_CELLS = 4  # the start is searched on whole cells this far around no shift
SEARCH_SAMPLES = 10_000  # ... on this many samples


class CoregError(ArchaeoOrthoError, ValueError):
    """The co-registration cannot run with the given rasters or points; the message names them."""


@dataclass(frozen=True)
class CoregOptions:
    """What the co-registration fits and how long it iterates: the shift and dz, with ``tilt`` a plane and with
    ``dome`` a quadratic; at most ``max_iterations`` steps, until the shift changes by less than ``tolerance``
    cells."""

    tilt: bool = True
    dome: bool = False
    max_iterations: int = 20
    tolerance: float = 0.01


@dataclass
class HeightGrid:
    """Heights in metres on a north-up grid: a 2-D array, its GDAL geotransform, the value that means no height
    (besides NaN; None: NaN only), and what it is called in messages ("" : the role's name, "DEM" or "reference
    DEM")."""

    array: np.ndarray
    transform: Sequence[float]
    nodata: Optional[float] = None
    name: str = ""


@dataclass
class CoregResult:
    shift: Tuple[float, float, float]  # dx, dy, dz (metres): add to the DEM's coordinates / heights
    tilt: Tuple[float, float] = (0.0, 0.0)  # a, b: dz += a (x - x0) + b (y - y0)
    dome: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # cxx, cxy, cyy (1/m)
    origin: Tuple[float, float] = (0.0, 0.0)  # x0, y0
    iterations: int = 0
    converged: bool = False
    nmad_before: float = math.nan  # NMAD of dh over the compared cells, before and after (metres)
    nmad_after: float = math.nan
    median_before: float = math.nan
    median_after: float = math.nan
    n_cells: int = 0  # stable cells (or points) in the final fit
    n_compared: int = 0  # cells (of the fit's subset) or points where both surfaces have a height
    stable_fraction: float = 0.0  # n_cells / n_compared
    cell: float = 0.0  # the comparison grid's cell (metres); the reference's cell for points
    shift_sigma: Tuple[float, float, float] = (math.nan, math.nan, math.nan)  # standard errors of dx, dy, dz
    horizontal_determined: bool = True  # False: terrain too flat, dx = dy = 0 held
    messages: List[str] = field(default_factory=list)

    def correction(self, x, y) -> np.ndarray:
        """The height to add at reference positions (x, y) (metres): dz + tilt + dome."""
        u = np.asarray(x, dtype=float) - self.origin[0]
        v = np.asarray(y, dtype=float) - self.origin[1]
        cxx, cxy, cyy = self.dome
        return self.shift[2] + self.tilt[0] * u + self.tilt[1] * v + cxx * u * u + cxy * u * v + cyy * v * v

    def apply(self, xyz) -> np.ndarray:
        """Points of the DEM's frame (N x 3) moved onto the reference."""
        p = np.array(xyz, dtype=float).reshape(-1, 3)
        p[:, 0] += self.shift[0]
        p[:, 1] += self.shift[1]
        p[:, 2] += self.correction(p[:, 0], p[:, 1])
        return p

    def apply_to_grid(self, z: np.ndarray, geotransform: Sequence[float]) -> Tuple[np.ndarray, Tuple[float, ...]]:
        """A DEM on the reference: (heights + correction as float32, the geotransform moved by (dx, dy)).  Row
        blocks, so no float64 copy of a large DEM is made."""
        gt = tuple(float(v) for v in geotransform)
        gt = (gt[0] + self.shift[0], gt[1], gt[2], gt[3] + self.shift[1], gt[4], gt[5])
        z = np.asarray(z)
        out = np.empty(z.shape, np.float32)
        xs = gt[0] + (np.arange(z.shape[1]) + 0.5) * gt[1]
        for r0 in range(0, z.shape[0], 256):
            r1 = min(z.shape[0], r0 + 256)
            ys = gt[3] + (np.arange(r0, r1) + 0.5) * gt[5]
            out[r0:r1] = z[r0:r1] + self.correction(xs[None, :], ys[:, None])
        return out, gt

    def as_dict(self) -> dict:
        """The result as plain JSON-ready values (for the manifest and the report)."""
        out = asdict(self)
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in out.items()}

    def summary(self) -> str:
        dx, dy, dz = self.shift
        return (f"shift dx {dx:.2f} m, dy {dy:.2f} m, dz {dz:.2f} m; tilt {self.tilt[0] * 1e3:.3f} / "
                f"{self.tilt[1] * 1e3:.3f} mm/m; NMAD {self.nmad_before:.2f} -> {self.nmad_after:.2f} m on "
                f"{self.n_cells} stable cells ({100 * self.stable_fraction:.0f} %), {self.iterations} iteration(s)"
                + ("" if self.converged else ", not converged"))


def nmad(values: np.ndarray) -> float:
    """Normalised median absolute deviation (1.4826 MAD) of the finite values; NaN for none."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return math.nan
    return float(1.4826 * np.median(np.abs(v - np.median(v))))


# ---------------------------------------------------------------------------
# the fit (shared by grids and points)
# ---------------------------------------------------------------------------

@dataclass
class _Model:
    """The terms besides the shift, on coordinates centred on ``origin`` and divided by ``scale``."""

    origin: Tuple[float, float]
    scale: float
    tilt: bool
    dome: bool

    @property
    def size(self) -> int:
        return 1 + (2 if self.tilt else 0) + (3 if self.dome else 0)

    def matrix(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        u = (x - self.origin[0]) / self.scale
        v = (y - self.origin[1]) / self.scale
        cols = [np.ones_like(u)]
        if self.tilt:
            cols += [u, v]
        if self.dome:
            cols += [u * u, u * v, v * v]
        return np.stack(cols, axis=1)

    def coefficients(self, p: np.ndarray) -> Tuple[float, Tuple[float, float], Tuple[float, float, float]]:
        """(dz, tilt, dome) in metres from the scaled parameters."""
        s = self.scale
        tilt = (float(p[1] / s), float(p[2] / s)) if self.tilt else (0.0, 0.0)
        k = 3 if self.tilt else 1
        dome = (float(p[k] / s ** 2), float(p[k + 1] / s ** 2), float(p[k + 2] / s ** 2)) if self.dome else (0.0,) * 3
        return float(p[0]), tilt, dome


# sample(shift, subset=None) -> (x, y, dh, gx, gy): reference positions, R - D there, the reference's gradient
# (NaN = no data), of every sample or of the indices ``subset``
Sampler = Callable[..., Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]]


def shorth(values: np.ndarray) -> Tuple[float, float]:
    """(centre, spread) of the shortest interval holding half of the finite values: its midpoint, and its length
    / 1.349 (the standard deviation for normal values, as the NMAD).  Unlike the median it stays on the larger
    population when up to half of the values are one block of outliers (40 % of the DSM under forest)."""
    v = np.sort(np.asarray(values, dtype=float)[np.isfinite(values)])
    if v.size < 2:
        return (float(v[0]) if v.size else math.nan), 0.0
    k = v.size // 2
    widths = v[k:] - v[: v.size - k]
    i = int(np.argmin(widths))
    return float(0.5 * (v[i] + v[i + k])), float(widths[i] / 1.349)


def _inliers(r: np.ndarray, usable: np.ndarray) -> np.ndarray:
    """The samples within OUTLIER_NMAD spreads of the residuals' shortest half."""
    ok = usable & np.isfinite(r)
    if not ok.any():
        return ok
    centre, spread = shorth(r[ok])
    return ok & (np.abs(r - centre) <= OUTLIER_NMAD * max(spread, 1e-6))


@dataclass
class _Step:
    d_shift: np.ndarray  # increment of the shift (metres)
    d_p: np.ndarray  # increment of the model's parameters
    inliers: np.ndarray  # bool over the samples
    cov: np.ndarray  # covariance of (sx, sy, p...) (normal-matrix inverse x the residual NMAD squared)
    change: float  # the largest height change of the model's increment over the inliers
    spread: float  # NMAD of the inliers' residuals after the step
    relief: float  # RMS height change of a one-cell shift over the inliers (RMS gradient x cell)


def _step(sample: Sampler, shift: np.ndarray, p: np.ndarray, model: _Model, usable: np.ndarray, horizontal: bool,
          cell: float) -> _Step:
    """One Gauss-Newton step at ``shift``, ``p``."""
    x, y, dh, gx, gy = sample(shift)
    m = model.matrix(x, y)
    r = dh - m @ p
    steep = np.hypot(gx, gy) > math.tan(math.radians(MAX_SLOPE_DEG))
    inl = _inliers(r, usable & ~steep & np.isfinite(gx) & np.isfinite(gy))
    n = int(inl.sum())
    if n < MIN_CELLS:
        raise CoregError(f"only {n} stable cells where both surfaces have a height (at least {MIN_CELLS} needed)")
    a = m[inl]
    if horizontal:
        a = np.column_stack([-gx[inl], -gy[inl], a])
    sol, *_ = np.linalg.lstsq(a, r[inl], rcond=None)
    spread = nmad(r[inl] - a @ sol)
    try:
        cov = np.linalg.inv(a.T @ a) * spread ** 2
    except np.linalg.LinAlgError:
        cov = np.full((a.shape[1], a.shape[1]), np.inf)
    if not horizontal:
        sol = np.r_[0.0, 0.0, sol]
        cov = np.pad(cov, ((2, 0), (2, 0)), constant_values=np.inf)
    change = float(np.max(np.abs(m[inl] @ sol[2:])))
    relief = float(np.sqrt(np.mean(gx[inl] ** 2 + gy[inl] ** 2))) * cell
    return _Step(sol[:2], sol[2:], inl, cov, change, spread, relief)


@dataclass
class _Samples:
    """What a fit compares: the sampler of height differences, its 'usable' mask, the comparison cell (metres)."""

    sample: Sampler
    usable: np.ndarray
    cell: float


def _iterate(samples: _Samples, model: _Model, options: CoregOptions, horizontal: bool, progress: Progress,
             shift: Optional[np.ndarray] = None, p: Optional[np.ndarray] = None):
    """Gauss-Newton from ``shift``, ``p`` (none, zeros) until the shift changes by less than ``tolerance`` cells
    and the model by less than a twentieth of the residual NMAD: (shift, parameters, iterations, converged, last
    step)."""
    sample, usable, cell = samples.sample, samples.usable, samples.cell
    max_iterations, tolerance = options.max_iterations, options.tolerance
    shift = np.zeros(2) if shift is None else np.array(shift, dtype=float)
    p = np.zeros(model.size) if p is None else np.array(p, dtype=float)
    st, it, converged = None, 0, False
    for it in range(1, max_iterations + 1):
        check_cancel(progress)
        st = _step(sample, shift, p, model, usable, horizontal, cell)
        size = float(np.hypot(*st.d_shift))
        if size > MAX_STEP_CELLS * cell:
            st.d_shift = st.d_shift * (MAX_STEP_CELLS * cell / size)
        shift, p = shift + st.d_shift, p + st.d_p
        progress.report(min(0.95, it / max_iterations), f"co-registration iteration {it}: shift {shift[0]:.2f}, "
                        f"{shift[1]:.2f} m")
        if size < tolerance * cell and st.change < max(0.05 * st.spread, 1e-4):
            converged = True
            break
    return shift, p, it, converged, st


def _search(sample: Sampler, usable: np.ndarray, cell: float) -> np.ndarray:
    """The start of the iterations: the shift, on whole cells within SEARCH_CELLS (every second cell, then the
    cells around the best), whose height differences have the narrowest shortest half (on a fixed subset of
    SEARCH_SAMPLES samples); no shift unless one is clearly better (a tenth narrower).  While the shift is large,
    changed areas (a forest on one side) are not told from the terrain by their residuals, and a least-squares
    step would follow them."""
    idx = np.flatnonzero(usable)
    if idx.size > SEARCH_SAMPLES:
        idx = np.sort(np.random.default_rng(1).choice(idx, SEARCH_SAMPLES, replace=False))

    def spread(i: int, j: int) -> float:
        dh = sample(np.array([i * cell, j * cell]), idx)[2]
        ok = np.isfinite(dh)
        return shorth(dh[ok])[1] if ok.sum() >= max(MIN_CELLS, 0.5 * idx.size) else math.inf

    k = SEARCH_CELLS
    tried = {(i, j): spread(i, j) for i in range(-k, k + 1, 2) for j in range(-k, k + 1, 2)}
    bi, bj = min(tried, key=tried.get)
    for i in range(bi - 1, bi + 2):
        for j in range(bj - 1, bj + 2):
            if (i, j) not in tried:
                tried[(i, j)] = spread(i, j)
    bi, bj = min(tried, key=tried.get)
    return np.array([bi * cell, bj * cell]) if tried[(bi, bj)] < 0.9 * tried[(0, 0)] else np.zeros(2)


def _staged(samples: _Samples, model: _Model, options: CoregOptions, progress: Progress):
    """:func:`_iterate` with the shift and dz alone first, then the whole model from there: while the shift is
    large, changed areas (a forest on one side) are not yet told from the terrain and a tilt would take them up."""
    start = _search(samples.sample, samples.usable, samples.cell)
    if model.size == 1:
        return _iterate(samples, model, options, True, progress, start)
    plain = _Model(model.origin, model.scale, False, False)
    shift, p0, it0, _, _ = _iterate(samples, plain, replace(options, tolerance=0.1), True, progress, start)
    p = np.zeros(model.size)
    p[0] = p0[0]
    shift, p, it, converged, st = _iterate(samples, model, options, True, progress, shift, p)
    return shift, p, it0 + it, converged, st


def _fit(samples: _Samples, model: _Model, options: CoregOptions, progress: Progress) -> CoregResult:
    """The co-registration and its statistics.  The shift is dropped (and the heights fitted again) when the
    terrain cannot fix it: its standard error over UNDETERMINED_CELLS cells, or a one-cell shift changing the
    heights by less than the residual NMAD (the gradient is then mostly noise)."""
    messages: List[str] = []
    sample, usable, cell = samples.sample, samples.usable, samples.cell
    _, _, dh0, _, _ = sample(np.zeros(2))
    before = dh0[usable & np.isfinite(dh0)]
    shift, p, it, converged, st = _staged(samples, model, options, progress)
    horizontal = True
    sigma = math.sqrt(max(st.cov[0, 0], st.cov[1, 1], 0.0))
    if not (sigma <= UNDETERMINED_CELLS * cell) or st.relief < FLAT_NMADS * st.spread:
        horizontal = False
        messages.append(f"the terrain is too flat, or the surfaces differ too much (a one-cell shift changes the "
                        f"heights by {st.relief:.2g} m RMS, the residuals spread {st.spread:.2g} m), to determine a "
                        "horizontal shift: only the heights were co-registered (dx = dy = 0)")
        shift, p, it, converged, st = _iterate(samples, model, options, False, progress)
    # the vertical bias as the median of the stable residuals, the statistics
    x, y, dh, gx, gy = sample(shift)
    r = dh - model.matrix(x, y) @ p
    steep = np.hypot(gx, gy) > math.tan(math.radians(MAX_SLOPE_DEG))
    inl = _inliers(r, usable & ~steep)
    if inl.sum() >= MIN_CELLS:
        p[0] += float(np.median(r[inl]))
    r = dh - model.matrix(x, y) @ p
    after = r[usable & np.isfinite(r)]
    dz, tilt, dome = model.coefficients(p)
    if not converged:
        messages.append(f"not converged after {options.max_iterations} iterations (last shift change "
                        f"{float(np.hypot(*st.d_shift)):.3g} m): the surfaces may differ by more than a shift and a "
                        "tilt, or share too little stable terrain")
    n_cmp = int(after.size)
    return CoregResult(
        shift=(float(shift[0]), float(shift[1]), dz), tilt=tilt, dome=dome, origin=model.origin, iterations=it,
        converged=converged, nmad_before=nmad(before), nmad_after=nmad(after),
        median_before=float(np.median(before)) if before.size else math.nan,
        median_after=float(np.median(after)) if after.size else math.nan, n_cells=int(inl.sum()),
        n_compared=n_cmp, stable_fraction=float(inl.sum()) / max(n_cmp, 1), cell=float(cell),
        shift_sigma=tuple(float(math.sqrt(max(v, 0.0))) if math.isfinite(v) else math.nan
                          for v in np.diag(st.cov)[:3]),
        horizontal_determined=horizontal, messages=messages)


# ---------------------------------------------------------------------------
# rasters: one comparison grid
# ---------------------------------------------------------------------------

@dataclass
class _Source:
    ds: object  # gdal.Dataset
    name: str
    wkt: str
    gt: Tuple[float, ...]
    width: int
    height: int
    nodata: Optional[float]
    zscale: float = 1.0  # metres per height unit

    @property
    def cell(self) -> float:
        return max(abs(self.gt[1]), abs(self.gt[5]))

    @property
    def bounds(self) -> Tuple[float, float, float, float]:
        xs = (self.gt[0], self.gt[0] + self.width * self.gt[1])
        ys = (self.gt[3], self.gt[3] + self.height * self.gt[5])
        return min(xs), min(ys), max(xs), max(ys)


def _gdal():
    from osgeo import gdal, osr

    gdal.UseExceptions()
    osr.UseExceptions()
    return gdal, osr


def _check_transform(gt: Sequence[float], name: str) -> Tuple[float, ...]:
    gt = tuple(float(v) for v in gt)
    if len(gt) != 6 or not all(math.isfinite(v) for v in gt):
        raise CoregError(f"the {name} has no valid geotransform ({gt})")
    if gt[2] or gt[4]:
        raise CoregError(f"the {name} is rotated (geotransform {gt}): warp it to a north-up grid first")
    if gt[1] <= 0 or gt[5] >= 0:
        raise CoregError(f"the {name} is not north-up with positive cells (geotransform {gt})")
    return gt


def _array_source(arr, gt, nodata: Optional[float], name: str) -> _Source:
    """A MEM dataset (float32, NaN = nodata) holding ``arr``."""
    gdal, _ = _gdal()
    a = np.asarray(arr)
    if a.ndim != 2 or min(a.shape) < 2:
        raise CoregError(f"the {name} must be a 2-D array of at least 2 x 2 cells, got shape {a.shape}")
    gt = _check_transform(gt, name)
    ds = gdal.GetDriverByName("MEM").Create("", a.shape[1], a.shape[0], 1, gdal.GDT_Float32)
    ds.SetGeoTransform(gt)
    band = ds.GetRasterBand(1)
    band.SetNoDataValue(float("nan"))
    for r0 in range(0, a.shape[0], 1024):  # row blocks: no float32 copy of the whole array at once
        block = a[r0:r0 + 1024].astype(np.float32)
        if nodata is not None:
            block[block == np.float32(nodata)] = np.nan
        band.WriteArray(block, 0, r0)
    if not _has_data(ds):
        raise CoregError(f"the {name} has no height (every cell is nodata)")
    return _Source(ds, name, "", gt, a.shape[1], a.shape[0], float("nan"))


def _has_data(ds) -> bool:
    band = ds.GetRasterBand(1)
    nd = band.GetNoDataValue()
    step = max(1, ds.RasterYSize // 256)
    for r0 in range(0, ds.RasterYSize, step):
        row = band.ReadAsArray(0, r0, ds.RasterXSize, 1)
        ok = np.isfinite(row) if nd is None or not math.isfinite(nd) else (row != nd) & np.isfinite(row)
        if ok.any():
            return True
    for r0 in range(0, ds.RasterYSize, 512):  # all of it, in row blocks
        block = band.ReadAsArray(0, r0, ds.RasterXSize, min(512, ds.RasterYSize - r0))
        ok = np.isfinite(block) if nd is None or not math.isfinite(nd) else (block != nd) & np.isfinite(block)
        if ok.any():
            return True
    return False


def _warp(src: _Source, dst_wkt: str, gt: Tuple[float, ...], w: int, h: int, src_cell: float) -> np.ndarray:
    """``src`` on the grid (gt, w, h) of ``dst_wkt`` as float32 metres, NaN = nodata: averaged where its cells
    (``src_cell``, in the units of ``gt``) are finer, bilinear where not."""
    gdal, _ = _gdal()
    alg = "average" if src_cell < 0.75 * abs(gt[1]) else "bilinear"
    bounds = (gt[0], gt[3] + h * gt[5], gt[0] + w * gt[1], gt[3])
    kw = dict(format="MEM", outputBounds=bounds, width=w, height=h, resampleAlg=alg, outputType=gdal.GDT_Float32,
              dstNodata=float("nan"), multithread=False)
    if dst_wkt and src.wkt:
        kw.update(srcSRS=src.wkt, dstSRS=dst_wkt)
    if src.nodata is not None:
        kw["srcNodata"] = src.nodata
    try:
        out = gdal.Warp("", src.ds, options=gdal.WarpOptions(**kw))
    except RuntimeError as e:
        raise CoregError(f"cannot resample the {src.name} onto the comparison grid: {e}") from e
    z = out.GetRasterBand(1).ReadAsArray()
    out = None
    z[~np.isfinite(z)] = np.nan
    if src.zscale != 1.0:
        z *= np.float32(src.zscale)
    return z


def _dem_cell_in_ref_crs(dem: _Source, ref: _Source) -> Tuple[float, Tuple[float, float, float, float]]:
    """The DEM's cell size and bounds in the reference's CRS (a warped VRT when the CRSs differ)."""
    if not (dem.wkt and ref.wkt) or dem.wkt == ref.wkt:
        return dem.cell, dem.bounds
    gdal, _ = _gdal()
    vrt = gdal.AutoCreateWarpedVRT(dem.ds, dem.wkt, ref.wkt, gdal.GRA_Bilinear)
    if vrt is None:
        raise CoregError(f"cannot reproject the {dem.name} into the CRS of the {ref.name}")
    g = vrt.GetGeoTransform()
    xs = (g[0], g[0] + vrt.RasterXSize * g[1])
    ys = (g[3], g[3] + vrt.RasterYSize * g[5])
    return max(abs(g[1]), abs(g[5])), (min(xs), min(ys), max(xs), max(ys))


@dataclass
class _Pair:
    ref: np.ndarray  # float32 heights on the comparison grid (metres)
    gt: Tuple[float, ...]  # its geotransform (metres)
    dem: np.ndarray  # float32 heights on the comparison grid expanded by DEM_MARGIN_CELLS
    dem_gt: Tuple[float, ...]
    stable: Optional[np.ndarray]  # bool on the comparison grid, or None
    messages: List[str]


def _pair(dem: _Source, ref: _Source, stable: Optional[_Source], xy_unit: float = 1.0) -> _Pair:
    """Both surfaces on the comparison grid: the reference's lattice at the coarser cell size, over the overlap."""
    dem_cell, dem_bounds = _dem_cell_in_ref_crs(dem, ref)
    rb = ref.bounds
    xmin, ymin = max(rb[0], dem_bounds[0]), max(rb[1], dem_bounds[1])
    xmax, ymax = min(rb[2], dem_bounds[2]), min(rb[3], dem_bounds[3])
    cell = max(ref.cell, dem_cell)
    messages: List[str] = []
    if xmax - xmin < 2 * cell or ymax - ymin < 2 * cell:
        raise CoregError(f"the {dem.name} and the {ref.name} do not overlap (the {dem.name} spans "
                         f"{', '.join(f'{v:.1f}' for v in dem_bounds)}, the {ref.name} "
                         f"{', '.join(f'{v:.1f}' for v in rb)} in the reference's CRS): are they of the same place, "
                         "and is the CRS of each right?")
    cells = (xmax - xmin) * (ymax - ymin) / cell ** 2
    if cells > MAX_GRID_CELLS:
        factor = math.ceil(math.sqrt(cells / MAX_GRID_CELLS))
        cell *= factor
        messages.append(f"compared on a {cell:g} grid ({factor} x the finer cell) to bound memory")
    ox, oy = ref.gt[0], ref.gt[3]  # lattice of the reference
    c0, c1 = math.floor((xmin - ox) / cell + 1e-9), math.ceil((xmax - ox) / cell - 1e-9)
    r0, r1 = math.floor((oy - ymax) / cell + 1e-9), math.ceil((oy - ymin) / cell - 1e-9)
    gt = (ox + c0 * cell, cell, 0.0, oy - r0 * cell, 0.0, -cell)
    w, h = c1 - c0, r1 - r0
    m = DEM_MARGIN_CELLS
    dem_gt = (gt[0] - m * cell, cell, 0.0, gt[3] + m * cell, 0.0, -cell)
    z_ref = _warp(ref, ref.wkt, gt, w, h, ref.cell)
    z_dem = _warp(dem, ref.wkt, dem_gt, w + 2 * m, h + 2 * m, dem_cell)
    mask = None
    if stable is not None:  # the share of stable area in each cell (averaged whatever the mask's cell)
        mask = _warp(stable, ref.wkt, gt, w, h, 0.0) >= 0.5
    if not np.isfinite(z_ref).any():
        raise CoregError(f"the {ref.name} has no height where it overlaps the {dem.name}")
    if not np.isfinite(z_dem[m:m + h, m:m + w]).any():
        raise CoregError(f"the {dem.name} has no height where it overlaps the {ref.name}")
    if xy_unit != 1.0:
        gt = tuple(v * xy_unit for v in gt)
        dem_gt = tuple(v * xy_unit for v in dem_gt)
    return _Pair(z_ref, gt, z_dem, dem_gt, mask, messages)


def _grid_sampler(pair: _Pair, seed: int = 0) -> Tuple[Sampler, np.ndarray]:
    """The sampler over the comparison grid's cells with a reference height and gradient (at most
    MAX_FIT_CELLS of them, a fixed random subset), and its 'usable' mask (all True: the stable mask is applied
    here)."""
    gt = pair.gt
    gr, gc = np.gradient(pair.ref)  # float32, NaN next to nodata
    ok = np.isfinite(pair.ref) & np.isfinite(gr) & np.isfinite(gc)
    if pair.stable is not None:
        ok &= pair.stable
    idx = np.flatnonzero(ok)
    del ok
    if idx.size > MAX_FIT_CELLS:
        idx = np.sort(np.random.default_rng(seed).choice(idx, MAX_FIT_CELLS, replace=False))
    rows, cols = np.divmod(idx, pair.ref.shape[1])
    x = gt[0] + (cols + 0.5) * gt[1]
    y = gt[3] + (rows + 0.5) * gt[5]
    z = pair.ref.ravel()[idx].astype(np.float64)
    gx = gc.ravel()[idx].astype(np.float64) / gt[1]
    gy = gr.ravel()[idx].astype(np.float64) / gt[5]
    del gr, gc
    dg = pair.dem_gt

    def sample(shift: np.ndarray, sub: Optional[np.ndarray] = None):
        xs, ys, zs = (x, y, z) if sub is None else (x[sub], y[sub], z[sub])
        fc = (xs - shift[0] - dg[0]) / dg[1] - 0.5
        fr = (ys - shift[1] - dg[3]) / dg[5] - 0.5
        dh = zs - bilinear(pair.dem, fc, fr)
        return (xs, ys, dh, gx, gy) if sub is None else (xs, ys, dh, gx[sub], gy[sub])

    return sample, np.ones(idx.size, dtype=bool)


def _model(x: np.ndarray, y: np.ndarray, tilt: bool, dome: bool) -> _Model:
    if x.size == 0:
        raise CoregError("no cell where both surfaces have a height")
    x0, y0 = float(np.mean(x)), float(np.mean(y))
    scale = max(float(np.max(np.abs(x - x0))), float(np.max(np.abs(y - y0))), 1e-6)
    return _Model((x0, y0), scale, tilt, dome)


def _run_pair(pair: _Pair, names: str, options: CoregOptions, progress: Optional[Progress]) -> CoregResult:
    progress = progress or NullProgress()
    sample, usable = _grid_sampler(pair)
    x, y, dh, _, _ = sample(np.zeros(2))
    valid = np.isfinite(dh)
    if valid.sum() < MIN_CELLS:
        raise CoregError(f"too few cells to co-register {names}: {int(valid.sum())} cells where both have a "
                         f"height and the reference has a slope{' on stable terrain' if pair.stable is not None else ''}"
                         f" (at least {MIN_CELLS} needed at the comparison cell of {abs(pair.gt[1]):g})")
    model = _model(x[valid], y[valid], options.tilt, options.dome)
    try:
        result = _fit(_Samples(sample, usable, abs(pair.gt[1])), model, options, progress)
    except CoregError as e:
        raise CoregError(f"cannot co-register {names}: {e}") from e
    result.messages[:0] = pair.messages
    progress.report(1.0, "co-registration done")
    return result


def coregister_dems(dem: HeightGrid, ref: HeightGrid, *, stable_mask: Optional[np.ndarray] = None,
                    options: Optional[CoregOptions] = None, progress: Optional[Progress] = None) -> CoregResult:
    """Co-register ``dem`` onto ``ref`` (heights in metres, NaN or the grid's ``nodata`` = no height; north-up
    geotransforms, both in the same metric CRS).  ``stable_mask``: bool on the grid of ``ref``, True where the
    terrain did not change (optional; outliers are dropped anyway)."""
    dem_name, ref_name = dem.name or "DEM", ref.name or "reference DEM"
    d = _array_source(dem.array, dem.transform, dem.nodata, dem_name)
    r = _array_source(ref.array, ref.transform, ref.nodata, ref_name)
    s = None
    if stable_mask is not None:
        mask = np.asarray(stable_mask)
        if mask.shape != np.shape(ref.array):
            raise CoregError(f"the stable mask must have the shape of the {ref_name} {np.shape(ref.array)}, got "
                             f"{mask.shape}")
        s = _array_source(mask.astype(np.float32), ref.transform, None, "stable mask")
    pair = _pair(d, r, s)
    return _run_pair(pair, f"the {dem_name} and the {ref_name}", options or CoregOptions(), progress)


# ---------------------------------------------------------------------------
# files: CRS and units
# ---------------------------------------------------------------------------

def _height_unit(band, srs, path: str) -> Tuple[float, str]:
    """(metres per height unit, message): io.raster.height_unit's rule, the one every reader of heights follows
    (the band's unit type, else a vertical CRS's, else a projected CRS's axes in feet, else metres); a band
    unit that is neither metres nor feet is refused."""
    from ..io.raster import height_unit

    unit = (band.GetUnitType() or "").strip().lower()
    name, factor, where = height_unit(path)
    if unit and not where:  # a unit type height_unit does not know ('cm', 'dm', 'mm', ...)
        raise CoregError(f"{path}: the band's height unit '{unit}' is not metres or feet; convert it to metres first")
    if where and abs(factor - 1.0) > 1e-9:
        return float(factor), f"{path}: heights in {name} ({where}: {factor:g} m), converted to metres"
    return 1.0, ""


def _open_source(path: str, what: str, heights: bool = True) -> Tuple[_Source, float, List[str]]:
    """(source, metres per horizontal CRS unit, messages) of a raster file; CoregError naming it when it cannot
    be used (missing, unreadable, not heights (``heights``: core.io.raster.not_heights, an orthophoto given as a
    DEM), rotated, geographic CRS, no height)."""
    _, osr = _gdal()
    try:
        raster = RasterFile(path, f"the {what}")
    except RasterError as e:  # missing, unreadable, no band: the message names the file
        raise CoregError(str(e)) from e
    if raster.geotransform is None:
        raise CoregError(f"the {what} {path} has no georeferencing (no geotransform)")
    name = f"{what} {path}"
    if heights:
        check_heights(raster.dataset, f"the {name}", CoregError)
    gt = _check_transform(raster.geotransform, name)
    wkt = raster.crs_wkt
    ds = raster.dataset
    band = raster.band(1)
    srs = osr.SpatialReference(wkt=wkt) if wkt else None
    xy_unit, messages = 1.0, []
    if srs is not None:
        if srs.IsGeographic():
            raise CoregError(f"the {name} is in a geographic CRS ({srs.GetName()}, cells in degrees): slopes need "
                             "metres; reproject it to a projected CRS (e.g. its UTM zone) first")
        xy_unit = float(srs.GetLinearUnits() or 1.0)
    zscale, msg = _height_unit(band, srs, path)
    if msg:
        messages.append(msg)
    src = _Source(ds, name, wkt, gt, ds.RasterXSize, ds.RasterYSize, band.GetNoDataValue(), zscale)
    if not _has_data(ds):
        raise CoregError(f"the {name} has no height (every cell is nodata)")
    return src, xy_unit, messages


def _same_crs(a: str, b: str) -> bool:
    _, osr = _gdal()
    sa, sb = osr.SpatialReference(wkt=a), osr.SpatialReference(wkt=b)
    for srs in (sa, sb):
        srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    return bool(sa.IsSame(sb))


def coregister_rasters(dem_path: str, ref_path: str, *, stable_mask_path: Optional[str] = None,
                       options: Optional[CoregOptions] = None, progress: Optional[Progress] = None) -> CoregResult:
    """Co-register the DSM file ``dem_path`` onto the reference DEM file ``ref_path``.  Both are resampled onto
    the comparison grid by GDAL straight from the files (the DSM reprojected into the reference's CRS when they
    differ); heights in feet (band unit or vertical CRS) are converted to metres; the result is in metres (a
    reference CRS in feet: multiply its coordinates by the CRS's linear unit first)."""
    dem, dem_unit, m1 = _open_source(dem_path, "DSM")
    ref, ref_unit, m2 = _open_source(ref_path, "reference DEM")
    if bool(dem.wkt) != bool(ref.wkt):
        without = dem if not dem.wkt else ref
        raise CoregError(f"the {without.name} has no CRS while the other has one: it cannot be reprojected; assign "
                         "its CRS first (Raster > Projections > Assign Projection)")
    if dem.wkt and ref.wkt and dem.wkt != ref.wkt and _same_crs(dem.wkt, ref.wkt):
        dem.wkt = ref.wkt  # the same CRS spelt otherwise: no reprojection
    stable = None
    if stable_mask_path:
        stable, _, _ = _open_source(stable_mask_path, "stable-terrain mask", heights=False)
        stable.zscale = 1.0  # 0 / 1 flags, not heights in the CRS's unit
        if not stable.wkt and ref.wkt:
            stable.wkt = ref.wkt
    pair = _pair(dem, ref, stable, ref_unit)
    result = _run_pair(pair, f"{dem_path} and {ref_path}", options or CoregOptions(), progress)
    result.messages[:0] = m1 + m2
    return result


# ---------------------------------------------------------------------------
# points
# ---------------------------------------------------------------------------

def _ref_window(ref: np.ndarray, gt: Tuple[float, ...], xy: np.ndarray, margin: float):
    """The part of ``ref`` around the points (float32, NaN = nodata) and its geotransform."""
    h, w = ref.shape
    c0 = max(0, int(math.floor((xy[:, 0].min() - margin - gt[0]) / gt[1])))
    c1 = min(w, int(math.ceil((xy[:, 0].max() + margin - gt[0]) / gt[1])))
    r0 = max(0, int(math.floor((xy[:, 1].max() + margin - gt[3]) / gt[5])))
    r1 = min(h, int(math.ceil((xy[:, 1].min() - margin - gt[3]) / gt[5])))
    if c1 - c0 < 2 or r1 - r0 < 2:
        return None, gt
    win = np.asarray(ref[r0:r1, c0:c1], dtype=np.float32)
    return win, (gt[0] + c0 * gt[1], gt[1], 0.0, gt[3] + r0 * gt[5], 0.0, gt[5])


def coregister_points(points_xyz: np.ndarray, ref: HeightGrid, *, stable: Optional[np.ndarray] = None,
                      options: Optional[CoregOptions] = None, progress: Optional[Progress] = None) -> CoregResult:
    """Co-register points (N x 3, the block's sparse cloud in the reference's metric CRS) onto ``ref``: the
    reference is sampled bilinearly at the shifted points.  ``stable``: bool per point (optional)."""
    progress = progress or NullProgress()
    options = options or CoregOptions()
    ref_name, ref_nodata = ref.name or "reference DEM", ref.nodata
    pts = np.asarray(points_xyz, dtype=float)
    if pts.ndim != 2 or pts.shape[1] < 3:
        raise CoregError(f"the points must be an N x 3 array, got shape {pts.shape}")
    pts = pts[:, :3]
    keep = np.all(np.isfinite(pts), axis=1)
    gt = _check_transform(ref.transform, ref_name)
    win, wgt = _ref_window(np.asarray(ref.array), gt, pts[keep], DEM_MARGIN_CELLS * abs(gt[1]))
    if win is None:
        raise CoregError(f"the points do not overlap the {ref_name}")
    win = win.copy() if np.shares_memory(win, ref.array) else win
    if ref_nodata is not None:
        win[win == np.float32(ref_nodata)] = np.nan
    if not np.isfinite(win).any():
        raise CoregError(f"the {ref_name} has no height where the points are")
    gr, gc = np.gradient(win)
    gx, gy = gc / np.float32(wgt[1]), gr / np.float32(wgt[5])
    xy, z = pts[:, :2], pts[:, 2]

    def sample(shift: np.ndarray, sub: Optional[np.ndarray] = None):
        p, zs = (xy, z) if sub is None else (xy[sub], z[sub])
        qx, qy = p[:, 0] + shift[0], p[:, 1] + shift[1]
        fc = (qx - wgt[0]) / wgt[1] - 0.5
        fr = (qy - wgt[3]) / wgt[5] - 0.5
        return qx, qy, bilinear(win, fc, fr) - zs, bilinear(gx, fc, fr), bilinear(gy, fc, fr)

    usable = keep if stable is None else keep & np.asarray(stable, dtype=bool).reshape(-1)
    _, _, dh, _, _ = sample(np.zeros(2))
    valid = usable & np.isfinite(dh)
    if valid.sum() < MIN_CELLS:
        raise CoregError(f"too few points on the {ref_name}: {int(valid.sum())} with a reference height "
                         f"(at least {MIN_CELLS} needed)")
    model = _model(xy[valid, 0], xy[valid, 1], options.tilt, options.dome)
    try:
        result = _fit(_Samples(sample, usable, abs(gt[1])), model, options, progress)
    except CoregError as e:
        raise CoregError(f"cannot co-register the points onto the {ref_name}: {e}") from e
    progress.report(1.0, "co-registration done")
    return result


def reference_window(ref_path: str, xmin: float, ymin: float, xmax: float, ymax: float, *,
                     crs: Optional[str] = None, margin_cells: int = DEM_MARGIN_CELLS
                     ) -> Tuple[np.ndarray, Tuple[float, ...], List[str]]:
    """The part of the reference DEM file over a box (and ``margin_cells`` around it) as (float32 metres with
    NaN, its geotransform, messages): in ``crs`` (a metric CRS: the file is reprojected on the fly) or in the
    file's own metric CRS.  For :func:`coregister_points` and :func:`control_points_from_coregistration` without
    reading a national DEM whole."""
    from ..io.raster import DsmReader

    _, osr = _gdal()
    src, xy_unit, messages = _open_source(ref_path, "reference DEM")
    if crs:
        srs = osr.SpatialReference()
        try:
            srs.SetFromUserInput(crs)
        except RuntimeError as e:
            raise CoregError(f"unknown CRS {crs!r} for the points: {e}") from e
        if srs.IsGeographic() or abs((srs.GetLinearUnits() or 1.0) - 1.0) > 1e-9:
            raise CoregError(f"the points' CRS {crs!r} is not in metres: co-register in a projected metric CRS")
        if not src.wkt:
            raise CoregError(f"the {src.name} has no CRS: it cannot be reprojected into {crs!r}; assign its CRS "
                             "first")
    elif abs(xy_unit - 1.0) > 1e-9:
        raise CoregError(f"the {src.name} is in a CRS whose unit is {xy_unit:g} m: give the points' metric CRS so "
                         "that it is read reprojected")
    with DsmReader(ref_path, target_crs=crs) as reader:
        m = margin_cells * abs(reader.geotransform[1])
        arr, gt = reader.read_window(xmin - m, ymin - m, xmax + m, ymax + m)
    if arr.size == 0 or not np.isfinite(arr).any():
        raise CoregError(f"the {src.name} has no height over {xmin:.1f}, {ymin:.1f}, {xmax:.1f}, {ymax:.1f}: does it "
                         "cover the block, and is the CRS of each right?")
    return arr.astype(np.float32), tuple(gt), messages  # in metres: DsmReader converts the heights


def coregister_points_file(points_xyz: np.ndarray, ref_path: str, *, crs: Optional[str] = None,
                           stable: Optional[np.ndarray] = None, options: Optional[CoregOptions] = None,
                           progress: Optional[Progress] = None) -> CoregResult:
    """:func:`coregister_points` against the reference DEM file ``ref_path``, read over the points only
    (:func:`reference_window`; in ``crs``, the points' metric CRS, when given)."""
    pts = np.asarray(points_xyz, dtype=float)
    if pts.ndim != 2 or pts.shape[1] < 3:
        raise CoregError(f"the points must be an N x 3 array, got shape {pts.shape}")
    ok = np.all(np.isfinite(pts[:, :3]), axis=1)
    if not ok.any():
        raise CoregError("no point with finite coordinates")
    lo, hi = pts[ok, :2].min(axis=0), pts[ok, :2].max(axis=0)
    ref, gt, messages = reference_window(ref_path, lo[0], lo[1], hi[0], hi[1], crs=crs)
    result = coregister_points(pts, HeightGrid(ref, gt, name=f"reference DEM {ref_path}"), stable=stable,
                               options=options, progress=progress)
    result.messages[:0] = messages
    return result


# ---------------------------------------------------------------------------
# pseudo control points for the adjustment
# ---------------------------------------------------------------------------

@dataclass
class PseudoControl:
    """Control points derived from a co-registration: where the block has each point now (``block_xyz``, the
    DEM's or the sparse cloud's frame) and its reference coordinates (``xyz``: the shifted position and the
    reference's height there), with their standard deviations (metres)."""

    block_xyz: np.ndarray  # (n, 3)
    xyz: np.ndarray  # (n, 3)
    sigma_xy: np.ndarray  # (n,)
    sigma_z: np.ndarray  # (n,)
    index: Optional[np.ndarray] = None  # (n,) rows of the points they were chosen from (points only)

    def __len__(self) -> int:
        return len(self.xyz)


def _candidates(result: CoregResult, win: np.ndarray, wgt: Tuple[float, ...], dem, dem_gt, points):
    """(block x, y, z, reference x, y, roughness, point index or None) of the candidate positions: every point,
    or every reference cell over the DEM (its height sampled bilinearly, its roughness the largest height change
    half a reference cell around it)."""
    s = np.array(result.shift[:2])
    if points is not None:
        p = np.asarray(points, dtype=float)[:, :3]
        return p[:, 0], p[:, 1], p[:, 2], p[:, 0] + s[0], p[:, 1] + s[1], np.zeros(len(p)), np.arange(len(p))
    gt = _check_transform(dem_gt, "DEM")
    cols = np.arange(win.shape[1])
    rows = np.arange(win.shape[0])
    qx = (wgt[0] + (cols[None, :] + 0.5) * wgt[1]) + np.zeros((rows.size, 1))
    qy = (wgt[3] + (rows[:, None] + 0.5) * wgt[5]) + np.zeros((1, cols.size))
    qx, qy = qx.ravel(), qy.ravel()
    px, py = qx - s[0], qy - s[1]
    arr = np.asarray(dem)

    def at(x, y):
        return bilinear(arr, (x - gt[0]) / gt[1] - 0.5, (y - gt[3]) / gt[5] - 0.5)

    zb = at(px, py)
    half = 0.5 * abs(wgt[1])
    rough = np.zeros_like(zb)
    for ex, ey in ((half, 0), (-half, 0), (0, half), (0, -half)):
        rough = np.fmax(rough, np.abs(at(px + ex, py + ey) - zb))
    return px, py, zb, qx, qy, rough, None


def _spread(x: np.ndarray, y: np.ndarray, score: np.ndarray, n: int) -> np.ndarray:
    """Indices of at most ``n`` candidates, the best-scored one in each block of a grid over their extent."""
    w = max(float(np.ptp(x)), 1e-9)
    h = max(float(np.ptp(y)), 1e-9)
    nx = max(1, int(round(math.sqrt(n * w / h))))
    ny = max(1, int(math.ceil(n / nx)))
    bx = np.minimum(((x - x.min()) / w * nx).astype(int), nx - 1)
    by = np.minimum(((y - y.min()) / h * ny).astype(int), ny - 1)
    block = by * nx + bx
    order = np.lexsort((score, block))
    first = np.r_[True, block[order][1:] != block[order][:-1]]
    best = order[first]
    return best[np.argsort(score[best])][:n]


def control_points_from_coregistration(result: CoregResult, ref: HeightGrid, *, dem: Optional[HeightGrid] = None,
                                       points: Optional[np.ndarray] = None, n: int = 25,
                                       ref_sigma_z: float = 0.0) -> PseudoControl:
    """Up to ``n`` well-distributed pseudo control points from ``result``: on flat, stable, well-measured cells
    (the residual after the co-registration within two NMADs, the block's surface smooth around it), one per
    block of a grid over the overlap.  Give the DEM (heights, NaN = nodata, with its geotransform) or the points
    (N x 3) the co-registration was made with.

    sigma_xy = max(a quarter of the comparison cell, 3 x the shift's standard error) (the cell size when the
    terrain could not fix the shift); sigma_z = hypot(NMAD after, tan(slope) x sigma_xy, ``ref_sigma_z``) (the
    reference's own systematic height error where it is known, e.g. a national DEM's stated accuracy: the NMAD
    holds only its random part)."""
    if (dem is None) == (points is None):
        raise CoregError("give either the DEM (with its geotransform) or the points for the pseudo control points")
    if dem is not None and dem.transform is None:
        raise CoregError("the DEM's geotransform is needed for the pseudo control points")
    gt = _check_transform(ref.transform, "reference DEM")
    ref_nodata = ref.nodata
    dem_array, dem_transform = (None, None) if dem is None else (dem.array, dem.transform)
    if points is not None:
        xy = np.asarray(points, dtype=float)[:, :2] + np.array(result.shift[:2])
    else:
        dgt = _check_transform(dem_transform, "DEM")
        hh, ww = np.shape(dem_array)
        xy = np.array([[dgt[0], dgt[3] + hh * dgt[5]], [dgt[0] + ww * dgt[1], dgt[3]]]) + np.array(result.shift[:2])
    win, wgt = _ref_window(np.asarray(ref.array), gt, xy[np.all(np.isfinite(xy), axis=1)], 0.0)
    if win is None:
        raise CoregError("the block does not overlap the reference DEM")
    win = np.where(win == np.float32(ref_nodata), np.nan, win) if ref_nodata is not None else win
    px, py, zb, qx, qy, rough, index = _candidates(result, win, wgt, dem_array, dem_transform, points)
    fc, fr = (qx - wgt[0]) / wgt[1] - 0.5, (qy - wgt[3]) / wgt[5] - 0.5
    gr, gc = np.gradient(win)
    tan = np.hypot(bilinear(gc, fc, fr) / wgt[1], bilinear(gr, fc, fr) / wgt[5])
    zr = bilinear(win, fc, fr)
    r = zr - (zb + result.correction(qx, qy))
    noise = max(result.nmad_after, 1e-3)
    if result.horizontal_determined:
        sxy = max(0.25 * result.cell, 3 * math.hypot(result.shift_sigma[0], result.shift_sigma[1]))
    else:
        sxy = result.cell
    ok = np.isfinite(r) & np.isfinite(tan) & (np.abs(r) <= 2 * noise) & (rough <= 2 * noise + tan * abs(wgt[1]))
    if not ok.any():
        return PseudoControl(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0),
                             None if index is None else np.zeros(0, int))
    cand = np.flatnonzero(ok)
    score = (np.abs(r[cand]) + tan[cand] * sxy + rough[cand]) / noise
    pick = cand[_spread(qx[cand], qy[cand], score, n)]
    sz = np.sqrt(noise ** 2 + (tan[pick] * sxy) ** 2 + float(ref_sigma_z) ** 2)
    return PseudoControl(np.column_stack([px[pick], py[pick], zb[pick]]), np.column_stack([qx[pick], qy[pick],
                         zr[pick]]), np.full(pick.size, sxy), sz, None if index is None else index[pick])


__all__ = ["CoregError", "CoregOptions", "CoregResult", "HeightGrid", "PseudoControl",
           "control_points_from_coregistration", "coregister_dems", "coregister_points", "coregister_points_file", "coregister_rasters", "nmad", "reference_window", "shorth"]

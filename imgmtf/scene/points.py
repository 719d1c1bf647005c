"""Point arrays in a whole scene: ``imgmtf scan --target points``.

A mirror array on a field, a lamp array at night, a star field: the scene
is read tile by tile (a large scene is never loaded whole) and every
compact target of either polarity is found (:func:`compact_peaks`: a
local maximum of the background-subtracted scene, smoothed by a 1 px
Gaussian, at least ``DETECT_SNR`` times the noise, whose signal
``STAMP_RADIUS_PX`` away strays from a plane by under a fifth of its
height above it: a textured field's slope is such a plane; texture's bumps
and lines are not compact).  Targets of one polarity are grouped into arrays by their spacing
(:func:`group_arrays`: two targets are neighbours when each lies within
``LINK`` times its own nearest neighbour's distance of the other, or
within ``point_spacing_px`` when it is given; an array is a connected
group of at least ``MIN_ARRAY_POINTS``); each array's ROI (its targets'
box, ``margin_px`` wider) is read and measured by the point-target
pipeline (:func:`imgmtf.estimate.mtf2d.measure_points`), which judges
every target again and stacks the usable ones by their sub-pixel phases.

Each array gives two records (``scope`` "edge", the scan's word for a
candidate; ``target_id`` the array): across and along track, method
``points``, accepted, or one rejected record with the pipeline's reason.
The accepted arrays are combined per direction into the scene's rows
(``summary`` "points", :func:`summarise_points`), which a campaign store
keeps as method ``points``: a point array measures across and along track
directly, without the separability assumption that sections of edges need
(:mod:`.sections`), and settles their choice (:mod:`imgmtf.campaign.recommended`).
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from ..errors import ImageContentError, ImgmtfError
from ..estimate.results import finite
from ..inputs import MIN_SIZE_PX, saturation_levels
from ..io import RasterInfo, raster_info, read_raster
from ..kinds import get_kind
from ..records import CANDIDATE_SCOPE, SCENE_SCOPE, Record, utc_now
from ..safe_json import finite_values
from .combine import combine, precision_weights
from .settings import ScanSettings

#: the stamp's half side the targets are judged and measured on, px (as measure_points')
STAMP_RADIUS_PX = 4
#: the smallest peak over the noise worth grouping (measure_points refuses those under its own floor, 20)
DETECT_SNR = 10.0
#: a target's smoothed signal on its stamp's border, as a share of its peak, beyond which it is no point
MAX_BORDER_FRACTION = 0.2
#: neighbours lie within this many times each one's nearest-neighbour distance (a grid's diagonal is 1.41)
LINK = 1.5
#: the fewest targets an array has, found and used
MIN_ARRAY_POINTS = 4
#: the tiles' overlap, px: the background's blocks and the stamps of targets near a tile's edge
TILE_PAD_PX = 32
POINTS_SUMMARY = "points"
#: the reason of an array with too few usable targets
FEW_POINTS = "few-points"


def compact_peaks(image: np.ndarray, *, radius_px: int = STAMP_RADIUS_PX,
                  min_snr: float = DETECT_SNR) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every compact target on ``image``, bright or dark.

    Parameters
    ----------
    image : numpy.ndarray, shape (rows, cols)
        DN; NaN (nodata) is no target.
    radius_px : int, optional
        How far from its peak a target's smoothed signal must have fallen
        under a fifth of the peak, px (default 4).
    min_snr : float, optional
        The smallest peak over the noise (default 10).

    Returns
    -------
    xy : numpy.ndarray, shape (n, 2)
        The targets' peak pixels (x, y), px.
    snr : numpy.ndarray, shape (n,)
        Their peaks over the noise.
    bright : numpy.ndarray of bool, shape (n,)
        True for a bright target, False for a dark one.

    Examples
    --------
    >>> image = np.full((40, 40), 100.0); image[10, 12] += 500.0; image[30, 25] -= 400.0
    >>> image[:, 35:] = 900.0                                       # an edge: no point
    >>> image = np.random.default_rng(0).normal(image, 5.0)
    >>> xy, snr, bright = compact_peaks(image)
    >>> xy.tolist(), bright.tolist()
    ([[12, 10], [25, 30]], [True, False])
    """
    from scipy import ndimage

    from ..estimate.mtf2d.sources import background, robust_noise
    data = np.asarray(image, float)
    finite_pixels = np.isfinite(data)
    if not finite_pixels.any():
        return np.zeros((0, 2), int), np.zeros(0), np.zeros(0, bool)
    if not finite_pixels.all():
        data = np.where(finite_pixels, data, float(np.median(data[finite_pixels])))
    residual = data - background(data)
    noise = robust_noise(data)
    noise = noise if noise > 0 else 1e-12
    ring = np.ones((2 * radius_px + 1,) * 2, bool)
    ring[1:-1, 1:-1] = False
    dy, dx = (np.nonzero(ring)[0] - radius_px, np.nonzero(ring)[1] - radius_px)
    design = np.column_stack([np.ones(dx.size), dx, dy]).astype(float)
    found = []
    for sign in (1.0, -1.0):
        signal = sign * residual
        smoothed = ndimage.gaussian_filter(signal, 1.0)
        peaks = ((smoothed == ndimage.maximum_filter(smoothed, size=5)) & (smoothed > 0)
                 & (signal >= min_snr * noise) & finite_pixels)
        iy, ix = np.nonzero(peaks)
        # the border's departure from the plane fitted to it (a textured field's slope), against the peak's
        # height above that plane (as imgmtf.estimate.mtf2d.sources judges a target)
        padded = np.pad(smoothed, radius_px, mode="edge")
        ring_values = padded[iy[:, None] + radius_px + dy[None, :], ix[:, None] + radius_px + dx[None, :]]
        coefficients = ring_values @ np.linalg.pinv(design).T                # (n, 3)
        border = np.abs(ring_values - coefficients @ design.T).max(axis=1, initial=0.0)
        compact = border <= MAX_BORDER_FRACTION * (smoothed[iy, ix] - coefficients[:, 0])
        found.append((ix[compact], iy[compact], signal[iy, ix][compact] / noise, np.full(compact.sum(), sign > 0)))
    x, y, snr, bright = (np.concatenate(parts) for parts in zip(*found))
    order = np.lexsort((x, y))
    return np.column_stack([x, y])[order], snr[order], bright[order]


def group_arrays(xy: np.ndarray, *, spacing_px: float | None = None,
                 min_points: int = MIN_ARRAY_POINTS) -> list[np.ndarray]:
    """The arrays among targets at ``xy``: connected groups of neighbours.

    Parameters
    ----------
    xy : numpy.ndarray, shape (n, 2)
        The targets (x, y), px.
    spacing_px : float, optional
        Neighbours lie within this distance, px; default: each within
        ``LINK`` times its own nearest neighbour's distance of the other
        (an array's spacing, whatever it is, and two arrays apart).
    min_points : int, optional
        The fewest targets of an array (default 4).

    Returns
    -------
    list of numpy.ndarray
        Each array's indices into ``xy``, largest array first.

    Examples
    --------
    >>> grid = np.array([(10 + 12 * i, 10 + 12 * j) for i in range(3) for j in range(3)], float)
    >>> other = grid + [200.0, 0.0]
    >>> stray = np.array([[100.0, 150.0], [400.0, 30.0]])
    >>> [a.tolist() for a in group_arrays(np.vstack([grid, other, stray]))]
    [[0, 1, 2, 3, 4, 5, 6, 7, 8], [9, 10, 11, 12, 13, 14, 15, 16, 17]]
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree
    xy = np.asarray(xy, float).reshape(-1, 2)
    n = len(xy)
    if n < max(min_points, 2):
        return []
    tree = cKDTree(xy)
    if spacing_px is not None:
        pairs = tree.query_pairs(float(spacing_px), output_type="ndarray")
    else:
        nearest = tree.query(xy, k=2)[0][:, 1]
        reach = tree.query_ball_point(xy, LINK * nearest)
        pairs = np.array([(i, j) for i, near in enumerate(reach) for j in near if j > i], int).reshape(-1, 2)
        if len(pairs):
            d = np.hypot(*(xy[pairs[:, 0]] - xy[pairs[:, 1]]).T)
            pairs = pairs[d <= LINK * np.minimum(nearest[pairs[:, 0]], nearest[pairs[:, 1]])]
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n)) if len(pairs) else \
        coo_matrix((n, n))
    _, labels = connected_components(graph, directed=False)
    groups = [np.flatnonzero(labels == label) for label in np.unique(labels)]
    groups = [g for g in groups if len(g) >= min_points]
    return sorted(groups, key=lambda g: (-len(g), int(g[0])))


def find_peaks(path: str, info: RasterInfo, settings: ScanSettings) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`compact_peaks` over the whole scene, read tile by tile (each
    padded by ``TILE_PAD_PX``, its targets kept where its core holds them)."""
    tile = settings.tile_px
    parts = []
    for y0 in range(0, info.height, tile):
        for x0 in range(0, info.width, tile):
            wx, wy = max(x0 - TILE_PAD_PX, 0), max(y0 - TILE_PAD_PX, 0)
            wx1, wy1 = min(x0 + tile + TILE_PAD_PX, info.width), min(y0 + tile + TILE_PAD_PX, info.height)
            data = read_raster(path, settings.band, window=(wx, wy, wx1 - wx, wy1 - wy)).data
            xy, snr, bright = compact_peaks(data)
            xy = xy + np.array([wx, wy])
            core = (xy[:, 0] >= x0) & (xy[:, 0] < x0 + tile) & (xy[:, 1] >= y0) & (xy[:, 1] < y0 + tile)
            parts.append((xy[core], snr[core], bright[core]))
    xy, snr, bright = (np.concatenate(p) for p in zip(*parts))
    return xy.reshape(-1, 2), snr, bright.astype(bool)


def array_roi(xy: np.ndarray, margin_px: int, info: RasterInfo) -> tuple[int, int, int, int]:
    """(x, y, w, h) of an array's targets' box, ``margin_px`` (at least the
    stamp and 2 px) wider each side, within the scene."""
    margin = max(int(margin_px), STAMP_RADIUS_PX + 2)
    x0, y0 = np.floor(xy.min(axis=0)).astype(int) - margin
    x1, y1 = np.ceil(xy.max(axis=0)).astype(int) + margin + 1
    x0, y0 = max(int(x0), 0), max(int(y0), 0)
    x1, y1 = min(int(x1), info.width), min(int(y1), info.height)
    return x0, y0, x1 - x0, y1 - y0


def scan_points(path: str, settings: ScanSettings, track_azimuth_deg: float | None = 0.0) -> list[Record]:
    """Every point array of the scene, measured: two accepted records
    (across and along track) per usable array, one rejected record per
    other, accepted ones first, ranked by their interval's width at Nyquist.

    Parameters
    ----------
    path : str
        The scene.
    settings : ScanSettings
        How to scan (``target`` "points"; its ``point_spacing_px``, the
        ROI's ``margin_px``, the tiles, band, intervals, saturation).
    track_azimuth_deg : float or None, optional
        The ground track's direction (:func:`imgmtf.scene.measure.track_azimuth`).

    Returns
    -------
    list of Record
        The arrays' records (``site``: ``id``, ``rank``, ``target_id`` the
        array, ``x_px``, ``y_px`` its centre, ``roi``, ``points_found``).

    Raises
    ------
    ImgmtfError
        The scene cannot be read, or is too small.

    Examples
    --------
    >>> records = scan_points("mirrors.tif", ScanSettings("points"))      # doctest: +SKIP
    >>> [(r.site["target_id"], r.figures["direction"]) for r in records if r.ok]  # doctest: +SKIP
    [(1, 'along-track'), (1, 'across-track')]
    """
    run_utc = utc_now()
    info = raster_info(path)
    if min(info.width, info.height) < MIN_SIZE_PX:
        raise ImageContentError(f"{path}: the scene is {info.width} x {info.height} px; a point array needs "
                                f"at least {MIN_SIZE_PX} x {MIN_SIZE_PX}")
    xy, _, bright = find_peaks(path, info, settings)
    spacing = settings.point_spacing_px
    params = {**settings.measure_settings().params(), "track_azimuth_deg": track_azimuth_deg,
              "scan": settings.as_dict()}
    kind = get_kind(settings.target)
    estimators = {polarity: kind.make_estimator(settings.method, intervals=settings.intervals, transfer="linear",
                                                polarity=polarity, stamp_radius_px=STAMP_RADIUS_PX)
                  for polarity in ("bright", "dark")}
    arrays = []
    for polarity, members in (("bright", bright), ("dark", ~bright)):
        index = np.flatnonzero(members)
        arrays += [(polarity, index[g]) for g in group_arrays(xy[index], spacing_px=spacing)]
    arrays.sort(key=lambda a: (int(xy[a[1]][:, 1].min()), int(xy[a[1]][:, 0].min())))
    records: list[Record] = []
    for number, (polarity, members) in enumerate(arrays, start=1):
        roi = array_roi(xy[members], settings.margin_px, info)
        site = {"scope": CANDIDATE_SCOPE, "target_id": number,
                "x_px": round(float(xy[members, 0].mean()), 2), "y_px": round(float(xy[members, 1].mean()), 2),
                "roi": list(roi), "points_found": int(len(members)), "polarity": polarity}
        records += _measured_array(path, settings, estimators[polarity], roi, site, params, run_utc,
                                   track_azimuth_deg)
    return _ranked(records)


def _measured_array(path, settings, estimator, roi, site, params, run_utc, track) -> list[Record]:
    """One array's records: across and along, or why it was rejected."""
    try:
        raster = read_raster(path, settings.band, window=roi)
        result = estimator(raster.data, gsd_m=raster.gsd_m, dtype=raster.dtype, track_azimuth_deg=track,
                           saturation=settings.saturation or saturation_levels(raster.dtype))
        result = replace(result, roi=roi)
        site = {**site, "point_targets": point_targets(result.sources, roi)}
        if len(result.used) < MIN_ARRAY_POINTS:
            counts = ", ".join(f"{n} {why}" for why, n in sorted(result.refusal_counts().items())) or "none refused"
            raise ImageContentError(f"{path}: the array at ({site['x_px']:.0f}, {site['y_px']:.0f}) has "
                                    f"{len(result.used)} usable targets of the {len(result.sources)} features found in "
                                    f"its window ({counts}); an "
                                    f"array needs {MIN_ARRAY_POINTS}", reason=FEW_POINTS)
    except ImgmtfError as exc:
        return [Record.failed(path, settings.band, settings.target, settings.method, exc, params=params,
                              run_utc=run_utc, status="rejected", site={**site, "verdict_by": "pipeline"})]
    return [Record.measured(path, settings.band, summary, params=params, run_utc=run_utc, status="accepted",
                            site=dict(site), measurement=None)
            for summary in result.summaries(curves=True)]


def point_targets(sources, roi: tuple[int, int, int, int]) -> list[dict]:
    """Where each target of an array's window lies in the scene and whether
    it was used: ``x_px``, ``y_px`` (scene pixels, centres at integers) and
    ``status``, ``"used"`` or the reason it was refused (``faint``,
    ``clipped``...), for the overview's marks and the records.

    Examples
    --------
    >>> from imgmtf.estimate.mtf2d.sources import Source
    >>> point_targets([Source(3.25, 4.5, 80.0, "used"), Source(9.0, 2.0, 3.0, "faint")], (100, 200, 20, 20))
    [{'x_px': 103.25, 'y_px': 204.5, 'status': 'used'}, {'x_px': 109.0, 'y_px': 202.0, 'status': 'faint'}]
    """
    x0, y0 = roi[0], roi[1]
    return [{"x_px": round(x0 + float(s.x_px), 2), "y_px": round(y0 + float(s.y_px), 2), "status": s.status}
            for s in sources]


def _ranked(records: list[Record]) -> list[Record]:
    """Accepted records first, by their interval's width at Nyquist, then
    the rejected ones; ids in that order, ranks for the accepted."""
    def width(r: Record) -> float:
        low, high = r.figures.get("mtf_nyquist_ci") or (None, None)
        return math.inf if low is None or high is None else high - low
    accepted = sorted((r for r in records if r.ok), key=lambda r: (width(r), r.site["target_id"]))
    rejected = [r for r in records if not r.ok]
    out = []
    for k, r in enumerate(accepted + rejected, start=1):
        out.append(r.with_(site={"id": k, "rank": k if r.ok else None}))
    return out


def scan_point_arrays(path: str, settings: ScanSettings) -> tuple[list[Record], list[Record]]:
    """A scene's point arrays (:func:`scan_points`) and its rows per
    direction (:func:`summarise_points`): what ``imgmtf scan --target
    points`` reports and stores (the kind's ``scanner``).

    Parameters
    ----------
    path : str
        The scene.
    settings : ScanSettings
        How to scan; the track's direction as an edge scan takes it
        (:func:`imgmtf.scene.measure.track_azimuth`).

    Returns
    -------
    (list of Record, list of Record)
        The arrays' records and the scene's summaries.

    Examples
    --------
    >>> records, summaries = scan_point_arrays("mirrors.tif", ScanSettings("points"))   # doctest: +SKIP
    """
    from .measure import track_azimuth
    records = scan_points(path, settings, track_azimuth(raster_info(path), settings))
    return records, summarise_points(records)


def summarise_points(records: list[Record]) -> list[Record]:
    """The scene's rows per direction from its accepted arrays: ``summary``
    "points", ``scope`` "scene", status "combined"; the MTF at Nyquist and
    MTF50 combined by precision (:func:`imgmtf.scene.combine.combine`,
    their Birge ratio ``consistency``), the curve and FWHM averaged with
    the weights the MTF at Nyquist earned.

    Parameters
    ----------
    records : list of Record
        :func:`scan_points`' records.

    Returns
    -------
    list of Record
        One per direction (empty without an accepted array).

    Examples
    --------
    >>> rows = summarise_points(scan_points("mirrors.tif", ScanSettings("points")))   # doctest: +SKIP
    >>> [(r.figures["direction"], r.figures["n_arrays"]) for r in rows]                # doctest: +SKIP
    [('across-track', 1), ('along-track', 1)]
    """
    accepted = [r for r in records if r.ok and r.figures.get("mtf_nyquist") is not None]
    out = []
    order = ("across-track", "along-track", "image-x", "image-y")
    for direction in sorted({r.figures["direction"] for r in accepted}, key=lambda d: (d not in order, order.index(d)
                                                                                       if d in order else d)):
        group = [r for r in accepted if r.figures["direction"] == direction]
        out.append(_scene_row(group))
    return out


def _scene_row(group: list[Record]) -> Record:
    first = group[0]
    confidence = float((first.params.get("intervals") or {}).get("confidence") or 0.95)
    used = [int(r.figures.get("points_used") or 0) for r in group]
    intervals = [_pair(r.figures.get("mtf_nyquist_ci")) for r in group]
    nyquist = combine([r.figures["mtf_nyquist"] for r in group], intervals, used, confidence)
    fifty = [math.nan if r.figures.get("mtf50_cy_px") is None else r.figures["mtf50_cy_px"] for r in group]
    mtf50 = combine(fifty, [_pair(r.figures.get("mtf50_ci_cy_px")) for r in group], used, confidence) \
        if np.isfinite(fifty).any() else None
    weights = precision_weights(intervals, used, confidence) if len(group) > 1 else None
    figures: dict[str, Any] = {
        "summary": POINTS_SUMMARY, "direction": first.figures["direction"],
        "normal_angle_deg": first.figures.get("normal_angle_deg"),
        "n_arrays": len(group), "edge_ids": [r.site.get("id") for r in group],
        "points_used": int(sum(used)),
        "mtf_nyquist": finite(nyquist.value), "mtf_nyquist_ci": [finite(nyquist.low), finite(nyquist.high)],
        "mtf50_cy_px": finite(mtf50.value) if mtf50 else None,
        "mtf50_ci_cy_px": [finite(mtf50.low), finite(mtf50.high)] if mtf50 else [None, None],
        "consistency": finite(nyquist.consistency), "weights": nyquist.weights,
        "fwhm_px": finite(float(_average([r.figures.get("fwhm_px") for r in group], weights)[0])),
        "snr_min": finite(min(float(r.figures.get("snr") or math.nan) for r in group)),
        "alias_weight": finite(max(float(r.figures.get("alias_weight") or 0.0) for r in group)),
        "gsd_m": first.figures.get("gsd_m"),
        "warnings": sorted({w for r in group for w in r.figures.get("warnings") or []}),
    }
    gsd = figures["gsd_m"]
    if gsd and mtf50:
        figures["mtf50_cy_m"] = finite(mtf50.value / gsd)
    if gsd and figures["fwhm_px"] is not None:
        figures["fwhm_m"] = finite(figures["fwhm_px"] * gsd)
    frequencies = first.figures.get("frequencies_cy_px")
    curves = [r.figures.get("mtf") or [] for r in group]
    if frequencies and all(len(c) == len(frequencies) for c in curves):
        figures.update(frequencies_cy_px=list(frequencies),
                       mtf=finite_values(_average(curves, weights)))
    return Record(first.path, first.band, first.target, first.method, "combined", figures=figures,
                  site={"scope": SCENE_SCOPE},
                  params={"intervals": first.params.get("intervals"),
                          "track_azimuth_deg": first.params.get("track_azimuth_deg"),
                          "scan": first.params.get("scan")}, run_utc=first.run_utc)


def _pair(interval) -> tuple[float, float]:
    low, high = interval or (None, None)
    return (math.nan if low is None else low, math.nan if high is None else high)


def _average(values, weights) -> np.ndarray:
    """Mean over the first axis (None as NaN), ``weights`` equal when None."""
    x = np.array([[math.nan if v is None else v for v in np.atleast_1d(row)] for row in values], float)
    w = np.ones(len(x)) if weights is None else np.asarray(weights, float)
    w = np.where(np.isfinite(x), w[:, None], 0.0)
    total = w.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, np.sum(w * np.nan_to_num(x), axis=0) / total, np.nan)

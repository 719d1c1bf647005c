"""The campaign store: one OGC GeoPackage that GDAL and QGIS open directly,
holding every acquisition measured, its edges and its targets' results.

Layers
------
``acquisitions`` (a table without geometry)
    One row per acquisition (:class:`~imgmtf.campaign.acquisitions.Acquisition`):
    its id, file, SHA-256, time, platform, instrument, band, GSD, level,
    product, and provenance (settings as JSON, version, run time).
``edges``
    The measured edges: a scan's accepted half-edges (a LineString along the
    segment) or ``measure``'s chips (a Polygon: the ROI, or the chip's
    bounds), with their figures and the whole record as JSON.
``targets``
    The summaries per target or scene and direction, combined (``method``
    ``combined``), model-free across/along-track sections of the 2-D MTF
    (``sections``, under the named ``assumption``: separable, elliptical
    or the bracket of both), fitted (``fit``) or a point array's (``points``:
    across and along measured directly): MTF at Nyquist, MTF50,
    FWHM and RER with intervals (a Point at the target's centre); a fit's
    ``constrained`` (0 when no edge lay near that axis: the value is the
    other axis's, tied) and ``misfit``; ``recommended`` (1 on the row to
    quote for its direction, 0 on the others, never on a misfit) and
    ``recommended_because``.
``store_info`` (a table without geometry)
    ``schema_version`` and who created the store.

Figures (a row's ``plot``, an acquisition's ``overview``) are kept
relative to the store's folder, so that a store moved with its figures
still finds them (:func:`figure_path`).

Schema versions: 1 the first; 2 adds ``sensor_key`` (what identifies an
unnamed platform's sensor), ``recommended``, ``recommended_because`` and
``assumption``, and keeps figure paths relative to the store; 3 adds the
edges' ``feature_id`` and ``feature`` (the vector feature, with its
attributes as JSON, whose window a chip or candidate was measured in:
``--roi-file``).  Older
stores read (their missing columns None) and are upgraded when written.

Geometry is longitude/latitude (EPSG:4326, one CRS for scenes of any UTM
zone) when the scene is georeferenced, and empty otherwise (as a scan's
GeoJSON does); the pixel coordinates are columns of every row.

How rows are written: GDAL (through Fiona) encodes the rows as a
GeoPackage of their own, and one SQLite transaction on the store deletes
the acquisition's previous rows and copies the new ones in, so that a
reader never sees half an acquisition and re-adding one never duplicates
it.  Writers wait for one another (SQLite's busy timeout, then retries);
the layers have no spatial index, whose triggers need GDAL's SQL functions.
"""
from __future__ import annotations

import json
import math
import os
import sqlite3
import tempfile
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import FileWriteError, ImageReadError, ImgmtfError, ParameterError
from ..records import Record, json_safe
from ..version import __version__
from .acquisitions import Acquisition

if TYPE_CHECKING:
    from ..io import RasterInfo

SCHEMA_VERSION = 3
LAYERS = ("acquisitions", "edges", "targets")
BUSY_TIMEOUT_S = 30.0           # SQLite waits this long for another writer's lock...
WRITE_ATTEMPTS = 5              # ...and a write is tried this many times before it fails
SUMMARY_METHODS = ("combined", "sections", "fit", "points")

# column -> type ("str", "float", "int"); the acquisition's facts repeat in
# edges and targets so that each layer reads on its own in QGIS
_ACQUISITION_COLUMNS = {
    "acquisition_id": "str", "path": "str", "sha256": "str", "band": "str", "acquired_utc": "str",
    "platform": "str", "instrument": "str", "band_name": "str", "gsd_m": "float", "level": "str",
    "product_id": "str", "site": "str", "settings": "str", "sources": "str", "overview": "str",
    "imgmtf_version": "str", "run_utc": "str", "sensor_key": "str",
}
_REPEATED = {"acquisition_id": "str", "acquired_utc": "str", "platform": "str", "instrument": "str",
             "band_name": "str", "sensor_key": "str"}
_FIGURES = {
    "direction": "str", "normal_angle_deg": "float",
    "mtf_nyquist": "float", "mtf_nyquist_ci_low": "float", "mtf_nyquist_ci_high": "float",
    "mtf50_cy_px": "float", "mtf50_ci_low_cy_px": "float", "mtf50_ci_high_cy_px": "float",
    "fwhm_px": "float", "rer": "float", "gsd_m": "float", "resampling": "str", "target": "str",
}
_EDGE_COLUMNS = {
    **_REPEATED, "edge_id": "str", "scope": "str", "target_id": "int", "status": "str", "reason": "str",
    **_FIGURES, "snr": "float", "rows_used": "int", "x0_px": "float", "y0_px": "float", "x1_px": "float",
    "y1_px": "float", "roi_px": "str", "plot": "str", "record": "str", "feature_id": "str", "feature": "str",
}
_TARGET_COLUMNS = {
    **_REPEATED, "scope": "str", "target_id": "int", "method": "str", "status": "str", "reason": "str",
    **_FIGURES, "n_edges": "int", "consistency": "float", "constrained": "int", "misfit": "int",
    "recommended": "int", "recommended_because": "str", "assumption": "str", "snr_min": "float", "edge_ids": "str",
    "x_px": "float", "y_px": "float", "plot": "str", "record": "str",
}
SCHEMA: dict[str, dict[str, str]] = {"acquisitions": _ACQUISITION_COLUMNS, "edges": _EDGE_COLUMNS,
                                     "targets": _TARGET_COLUMNS}
_GEOMETRY_TYPES = {"acquisitions": None, "edges": "Unknown", "targets": "Point"}
_SQL_TYPES = {"str": "TEXT", "float": "REAL", "int": "INTEGER"}
_INTERVALS = {"mtf_nyquist_ci_low": ("mtf_nyquist_ci", 0), "mtf_nyquist_ci_high": ("mtf_nyquist_ci", 1),
              "mtf50_ci_low_cy_px": ("mtf50_ci_cy_px", 0), "mtf50_ci_high_cy_px": ("mtf50_ci_cy_px", 1)}


class StoreError(ImgmtfError):
    """A campaign store cannot be read or written (``reason`` ``store``).

    Parameters
    ----------
    message : str, optional
        One line naming the store and the problem.
    reason : str, optional
        Machine-readable code (default ``"store"``).

    Examples
    --------
    >>> from imgmtf import read_layer
    >>> read_layer("missing.gpkg", "edges")
    Traceback (most recent call last):
    imgmtf.campaign.store.StoreError: missing.gpkg: no such campaign store
    """

    reason = "store"


def write_acquisition(store_path: str | Path, acquisition: Acquisition, edges: Sequence[Record],
                      targets: Sequence[Record], *, info: RasterInfo | None = None) -> None:
    """Write one acquisition's rows into a campaign store, in one transaction.

    Creates the GeoPackage when it is missing; replaces every row of the
    same ``acquisition_id`` (re-adding a file with the same settings never
    duplicates it); waits for other writers (processes too) and loses
    nothing of theirs.

    Parameters
    ----------
    store_path : str or pathlib.Path
        The GeoPackage (``.gpkg``).
    acquisition : Acquisition
        The acquisition (:func:`~imgmtf.campaign.acquisitions.read_acquisition`).
    edges : sequence of Record
        Its measured edges: a scan's accepted half-edges, or ``measure``'s chips.
    targets : sequence of Record
        Its summaries (:func:`imgmtf.scene.combine.summarise_scan`, scope
        ``target`` or ``scene``), each with ``summary`` ``combined`` (the
        default when absent) or ``fit`` in its figures or site.
    info : imgmtf.io.RasterInfo, optional
        The scene's header, for map geometry (read from the acquisition's
        file when not given; no geometry when it cannot be read).

    Raises
    ------
    StoreError
        The store is not an imgmtf GeoPackage, was written by a newer
        imgmtf, or stayed locked by another writer through every attempt.
    FileWriteError
        The store cannot be written.
    ParameterError
        ``edges`` or ``targets`` hold something other than Records.

    Examples
    --------
    >>> from imgmtf.campaign.acquisitions import Acquisition
    >>> from imgmtf.records import Record
    >>> chip = Record("edge.tif", 1, "edge", "ESF", "ok", figures={"mtf_nyquist": 0.21, "roi": [0, 0, 64, 64]})
    >>> write_acquisition("site.gpkg", Acquisition("a1", "edge.tif", "00", "2024-05-01"), [chip], [])
    >>> [(row["acquisition_id"], row["mtf_nyquist"]) for row in read_layer("site.gpkg", "edges")]
    [('a1', 0.21)]
    """
    for record in (*edges, *targets):
        if not isinstance(record, Record):
            raise ParameterError(f"edges and targets must be Records, got {record!r}")
    store = Path(store_path)
    geo = _Georeference.of(acquisition.path, info)
    home = _home(store)
    rows = {"acquisitions": [_acquisition_row(acquisition, home)],
            "edges": [_edge_row(acquisition, r, geo, home) for r in edges],
            "targets": [_target_row(acquisition, r, geo, home) for r in targets]}
    ensure_store(store)
    with _scratch(store) as scratch:
        staged = Path(scratch) / "rows.gpkg"
        _write_layers(staged, rows)
        _retrying(store, lambda: _replace_rows(store, staged, acquisition.acquisition_id))


def ensure_store(store_path: str | Path) -> None:
    """Create an empty campaign store at ``store_path`` unless one is there
    (made aside and linked into place: two processes racing to create it
    end with one store).

    Raises
    ------
    FileWriteError
        The store's folder is not writable.
    """
    store = Path(store_path)
    if store.exists():
        return
    with _scratch(store) as scratch:
        fresh = Path(scratch) / "new.gpkg"
        _write_layers(fresh, {layer: [] for layer in LAYERS})
        _write_info(fresh)
        try:
            os.link(fresh, store)
        except FileExistsError:
            pass                    # another process made it first: use theirs
        except OSError as exc:
            raise FileWriteError(f"{store}: cannot create the store: {exc.strerror or exc}") from None


def read_layer(store_path: str | Path, layer: str) -> list[dict[str, Any]]:
    """The rows of a store's layer as dicts (column -> value; missing values
    None; the geometry left out), read through GDAL.

    A store of an older schema reads too: the columns it lacks are None.

    Parameters
    ----------
    store_path : str or pathlib.Path
        The campaign store (a GeoPackage).
    layer : str
        One of :data:`LAYERS`: ``acquisitions``, ``edges`` or ``targets``.

    Returns
    -------
    list of dict
        One per row, in the store's order.

    Raises
    ------
    StoreError
        The file is missing or is not a campaign store.
    ParameterError
        ``layer`` is not one of :data:`LAYERS`.

    Examples
    --------
    >>> from imgmtf.campaign.acquisitions import Acquisition
    >>> from imgmtf.records import Record
    >>> chip = Record("edge.tif", 1, "edge", "ESF", "ok", figures={"mtf_nyquist": 0.21, "roi": [0, 0, 64, 64]})
    >>> write_acquisition("site.gpkg", Acquisition("a1", "edge.tif", "00", "2024-05-01"), [chip], [])
    >>> [row["acquired_utc"] for row in read_layer("site.gpkg", "acquisitions")]
    ['2024-05-01']
    """
    import fiona
    from fiona.errors import FionaError

    if layer not in SCHEMA:
        raise ParameterError(f"layer must be one of {', '.join(LAYERS)}, got {layer!r}")
    store = Path(store_path)
    if not store.is_file():
        raise StoreError(f"{store}: no such campaign store")
    try:
        with fiona.open(store, layer=layer) as features:
            rows = [dict(feature.properties) for feature in features]
    except (FionaError, ValueError) as exc:
        raise StoreError(f"{store}: not a campaign store with a layer {layer!r} (GDAL: {exc})") from None
    return [{**dict.fromkeys(SCHEMA[layer]), **row} for row in rows]


def schema_version(store_path: str | Path) -> int:
    """The schema version a store records (0 for a store that records none)."""
    with _connect(Path(store_path)) as db:
        return _schema_version(db)


class _Georeference:
    """Pixel (x, y) -> longitude/latitude for a scene with a CRS; nothing without."""

    def __init__(self, transform=None, crs=None):
        self.transform, self.crs = transform, crs

    @classmethod
    def of(cls, path: str, info=None) -> _Georeference:
        if info is None:
            from ..io import raster_info
            try:
                info = raster_info(path)
            except (ImageReadError, ParameterError):
                return cls()
        return cls(info.transform, info.crs) if info.crs else cls()

    def geometry(self, points: Sequence[tuple[float, float]], kind: str) -> dict | None:
        """``points`` (pixel coordinates) as a GeoJSON-like geometry in
        longitude/latitude (``kind`` "Point", "LineString" or "Polygon"), or None."""
        if not self.crs or not points or any(v is None for p in points for v in p):
            return None
        from rasterio.warp import transform as warp
        mapped = [self.transform @ (x, y) for x, y in points]
        lon, lat = warp(self.crs, "EPSG:4326", [x for x, _ in mapped], [y for _, y in mapped])
        coordinates = [(float(a), float(b)) for a, b in zip(lon, lat)]
        shaped = {"Point": coordinates[0], "LineString": coordinates, "Polygon": [coordinates]}[kind]
        return {"type": kind, "coordinates": shaped}


def figure_path(store_path: str | Path, stored: str | None) -> Path | None:
    """Where a figure the store names is: a path relative to the store's
    folder (as this imgmtf writes them) or absolute; for a store older
    than schema 2, whose relative paths were the writer's working
    folder's, that folder (the current one) is tried second.  None when
    ``stored`` is empty; the path returned may not exist (the figure was
    moved or deleted): the caller says so.

    Examples
    --------
    >>> str(figure_path("/data/site/site.gpkg", "out/edges/edge1.png"))
    '/data/site/out/edges/edge1.png'
    """
    if not stored:
        return None
    path = Path(stored)
    if path.is_absolute():
        return path
    beside = Path(store_path).parent / path
    if beside.exists() or not path.exists():
        return beside
    return path                 # an older store's path, relative to where it was written from


def _home(store: Path) -> Path:
    """The store's folder, absolute, as figure paths are kept relative to it."""
    return store.parent.resolve()


def _relative(path: str | None, home: Path) -> str | None:
    """A figure's path (absolute or relative to the working folder) relative to ``home``;
    absolute when no relative path joins them (another drive)."""
    if not path:
        return None
    absolute = Path(path).resolve()
    try:
        return Path(os.path.relpath(absolute, home)).as_posix()
    except ValueError:
        return str(absolute)


def _acquisition_row(acquisition: Acquisition, home: Path) -> dict[str, Any]:
    row = acquisition.to_dict()
    row["overview"] = _relative(acquisition.overview, home)
    row["settings"] = json.dumps(row["settings"], sort_keys=True)
    row["sources"] = json.dumps(row["sources"], sort_keys=True)
    row["band"] = None if acquisition.band is None else str(acquisition.band)
    return row


def _common(acquisition: Acquisition, record: Record, home: Path) -> dict[str, Any]:
    flat = record.to_dict()
    row: dict[str, Any] = {key: getattr(acquisition, key) for key in _REPEATED}
    row.update({key: flat.get(key) for key in _FIGURES})
    for column, (key, index) in _INTERVALS.items():
        pair = flat.get(key) or (None, None)
        row[column] = pair[index]
    row.update(resampling=record.method, target=record.target, plot=_relative(record.plot, home),
               scope=flat.get("scope"), target_id=flat.get("target_id"),
               record=json.dumps(json_safe(flat), sort_keys=True, default=_jsonable))
    return row


def _edge_row(acquisition: Acquisition, record: Record, geo: _Georeference, home: Path) -> dict[str, Any]:
    flat = record.to_dict()
    row = _common(acquisition, record, home)
    row.update({key: flat.get(key) for key in ("status", "reason", "snr", "rows_used",
                                               "x0_px", "y0_px", "x1_px", "y1_px")})
    row["edge_id"] = None if flat.get("id") is None else str(flat["id"])
    row["feature_id"] = flat.get("feature_id")
    row["feature"] = (json.dumps(json_safe(flat["feature"]), sort_keys=True, default=_jsonable)
                      if flat.get("feature") is not None else None)
    roi = flat.get("roi")
    row["roi_px"] = json.dumps(roi) if roi else None
    if flat.get("x0_px") is not None:               # a scan's half-edge: its segment (pixel centres)
        ends = [(flat["x0_px"] + 0.5, flat["y0_px"] + 0.5), (flat["x1_px"] + 0.5, flat["y1_px"] + 0.5)]
        row["geometry"] = geo.geometry(ends, "LineString")
    else:                                           # a chip: its ROI, or the whole image
        x, y, w, h = roi if roi else (0, 0, *_size(acquisition.path))
        corners = [(x, y), (x + w, y), (x + w, y + h), (x, y + h), (x, y)]
        row["geometry"] = geo.geometry(corners, "Polygon") if w else None
    return row


def _target_row(acquisition: Acquisition, record: Record, geo: _Georeference, home: Path) -> dict[str, Any]:
    flat = record.to_dict()
    method = flat.get("summary") or "combined"
    if method not in SUMMARY_METHODS:
        raise ParameterError(f"a target's summary must be one of {', '.join(SUMMARY_METHODS)}, got {method!r}")
    row = _common(acquisition, record, home)
    row.update({key: flat.get(key) for key in ("status", "reason", "n_edges", "consistency", "constrained",
                                               "misfit", "recommended", "recommended_because", "assumption",
                                               "snr_min", "x_px", "y_px")})
    if row["recommended"] is not None and row["misfit"]:
        row["recommended"] = False          # a model that does not fit the data is never the value to quote
    row["method"] = method
    row["edge_ids"] = json.dumps(flat["edge_ids"], default=_jsonable) if flat.get("edge_ids") is not None else None
    centre = [(flat["x_px"] + 0.5, flat["y_px"] + 0.5)] if flat.get("x_px") is not None else []
    row["geometry"] = geo.geometry(centre, "Point")
    return row


def _size(path: str) -> tuple[int, int]:
    """(width, height) of the image, (0, 0) when it cannot be read."""
    from ..io import raster_info
    try:
        info = raster_info(path)
    except (ImageReadError, ParameterError):
        return 0, 0
    return info.width, info.height


def _jsonable(value):
    return value.tolist() if hasattr(value, "tolist") else str(value)


def _write_layers(path: Path, rows: Mapping[str, list[dict[str, Any]]]) -> None:
    """Write ``rows`` per layer into a new GeoPackage at ``path`` with GDAL
    (through Fiona), each layer in the schema of :data:`SCHEMA`."""
    import fiona

    for layer, columns in SCHEMA.items():
        geometry = _GEOMETRY_TYPES[layer]
        schema = {"geometry": geometry or "None", "properties": dict(columns)}
        crs = "EPSG:4326" if geometry else None
        with fiona.open(path, "w", driver="GPKG", layer=layer, schema=schema, crs=crs, SPATIAL_INDEX="NO") as out:
            out.writerecords([_feature(row, columns) for row in rows.get(layer, [])])


def _feature(row: Mapping[str, Any], columns: Mapping[str, str]):
    import fiona

    properties = {name: _typed(row.get(name), kind) for name, kind in columns.items()}
    shape = row.get("geometry")
    geometry = fiona.Geometry(type=shape["type"], coordinates=shape["coordinates"]) if shape else None
    return fiona.Feature(geometry=geometry, properties=fiona.Properties(**properties))


def _typed(value, kind: str):
    """A value as its column's type; None for missing and non-finite numbers."""
    if value is None:
        return None
    if kind == "str":
        return str(value)
    number = float(value)
    if not math.isfinite(number):
        return None
    return int(number) if kind == "int" else number


def _write_info(path: Path) -> None:
    """The ``store_info`` table of a new store: its schema version and maker."""
    import fiona

    schema = {"geometry": "None", "properties": {"key": "str", "value": "str"}}
    items = {"schema_version": str(SCHEMA_VERSION), "created_by": f"imgmtf {__version__}"}
    with fiona.open(path, "w", driver="GPKG", layer="store_info", schema=schema) as out:
        out.writerecords([fiona.Feature(geometry=None, properties=fiona.Properties(key=k, value=v))
                          for k, v in items.items()])


def _scratch(store: Path) -> tempfile.TemporaryDirectory:
    """A temporary folder beside the store (one file system: the new store is linked from it)."""
    if not store.parent.is_dir():
        raise FileWriteError(f"{store}: cannot write: folder {store.parent} does not exist")
    try:
        return tempfile.TemporaryDirectory(prefix=".imgmtf-store-", dir=store.parent)
    except OSError as exc:
        raise FileWriteError(f"{store}: cannot write in {store.parent}: {exc.strerror or exc}") from None


def _connect(store: Path) -> sqlite3.Connection:
    try:
        db = sqlite3.connect(store, timeout=BUSY_TIMEOUT_S, isolation_level=None)
        db.execute("SELECT count(*) FROM gpkg_contents").fetchone()
    except sqlite3.DatabaseError as exc:
        raise StoreError(f"{store}: not a GeoPackage campaign store ({exc})") from None
    return db


def _schema_version(db: sqlite3.Connection) -> int:
    try:
        row = db.execute("SELECT value FROM store_info WHERE key = 'schema_version'").fetchone()
    except sqlite3.OperationalError:
        return 0
    return int(row[0]) if row else 0


def _retrying(store: Path, action) -> None:
    """``action`` tried again while another writer holds the store's lock."""
    for attempt in range(WRITE_ATTEMPTS):
        try:
            action()
            return
        except sqlite3.DatabaseError as exc:
            if "locked" not in str(exc) and "busy" not in str(exc):
                raise FileWriteError(f"{store}: cannot write: {exc}") from None
            if attempt == WRITE_ATTEMPTS - 1:
                raise StoreError(f"{store}: still locked by another writer after {WRITE_ATTEMPTS} attempts "
                                 f"of {BUSY_TIMEOUT_S:.0f} s") from None
            time.sleep(0.5 * (attempt + 1))


def _replace_rows(store: Path, staged: Path, acquisition_id: str) -> None:
    db = _connect(store)
    try:
        db.execute("ATTACH DATABASE ? AS staged", (str(staged),))
        db.execute("BEGIN IMMEDIATE")
        try:
            version = _schema_version(db)
            if version > SCHEMA_VERSION:
                raise StoreError(f"{store}: written by a newer imgmtf (store schema {version}, "
                                 f"this imgmtf knows {SCHEMA_VERSION}); upgrade imgmtf to add to it")
            _upgrade(db, version)
            now = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
            for layer in LAYERS:
                columns = [c for c in _table_columns(db, "staged", layer) if c != "fid"]
                names = ", ".join(f'"{c}"' for c in columns)
                db.execute(f'DELETE FROM main."{layer}" WHERE acquisition_id = ?', (acquisition_id,))
                db.execute(f'INSERT INTO main."{layer}" ({names}) SELECT {names} FROM staged."{layer}"')
                db.execute("UPDATE main.gpkg_contents SET last_change = ? WHERE table_name = ?", (now, layer))
            db.execute("COMMIT")
        except BaseException:
            db.execute("ROLLBACK")
            raise
    finally:
        db.close()


def _table_columns(db: sqlite3.Connection, schema: str, table: str) -> list[str]:
    return [row[1] for row in db.execute(f'PRAGMA {schema}.table_info("{table}")')]


def _upgrade(db: sqlite3.Connection, version: int) -> None:
    """Bring an older store to this schema: the columns it lacks added
    (their values None in its old rows), the version recorded."""
    for layer, columns in SCHEMA.items():
        have = set(_table_columns(db, "main", layer))
        for name, kind in columns.items():
            if name not in have:
                db.execute(f'ALTER TABLE main."{layer}" ADD COLUMN "{name}" {_SQL_TYPES[kind]}')
    if version < SCHEMA_VERSION:
        if not _table_columns(db, "main", "store_info"):
            raise StoreError("the store has no store_info table: it is not an imgmtf campaign store")
        db.execute("DELETE FROM store_info WHERE key = 'schema_version'")
        db.execute("INSERT INTO store_info (key, value) VALUES ('schema_version', ?)", (str(SCHEMA_VERSION),))

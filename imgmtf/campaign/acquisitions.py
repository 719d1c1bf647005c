"""What an acquisition is: one image file (one band of it) measured with
given settings, with when, by what and how it was taken.

:func:`read_acquisition` gathers the facts from three places, the first
that knows winning:

1. the caller's keyword arguments (the command line's ``--acquired``,
   ``--platform``, ``--instrument``, ``--band-name``);
2. the file's metadata, read through GDAL: the items ``ACQUISITION_DATETIME``,
   ``PLATFORM``, ``INSTRUMENT``, ``BAND_NAME``, ``PROCESSING_LEVEL`` (which
   ``imgmtf simulate --campaign`` writes), GDAL's IMAGERY domain
   (``SATELLITEID``, ``ACQUISITIONDATETIME``) and the band's description;
3. the standard product names (:func:`parse_product_name`): Landsat
   Collection 1/2 (``LC09_L1TP_181040_20211121_20211122_02_T1_B8.TIF``) and
   Sentinel-2 (``T32TNR_20250619T101559_B04_10m.jp2``, and the ``.SAFE``
   folder it sits in);

and last, for the time only, the TIFF tag ``TIFFTAG_DATETIME`` (when the
file was written, which is the acquisition time only for some cameras).
Where each fact came from is kept in :attr:`Acquisition.sources`.
"""
from __future__ import annotations

import hashlib
import json
import re
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import ImageReadError, ParameterError
from ..records import json_safe, utc_now
from ..version import __version__

if TYPE_CHECKING:
    from ..io import RasterInfo

# the facts an acquisition carries besides its file, in the order the CLI lists them
FACTS = ("acquired_utc", "platform", "instrument", "band_name", "level")

# default-domain metadata items that state a fact (imgmtf simulate --campaign writes the first four)
METADATA_ITEMS = {"acquired_utc": "ACQUISITION_DATETIME", "platform": "PLATFORM", "instrument": "INSTRUMENT",
                  "band_name": "BAND_NAME", "level": "PROCESSING_LEVEL"}

# Landsat: sensor letter and mission number -> platform, instrument
_LANDSAT_SENSORS = {"C": "OLI", "O": "OLI", "T": "TIRS", "E": "ETM+", "M": "MSS"}
_LANDSAT_SECOND_GENERATION = {"OLI": "OLI-2", "TIRS": "TIRS-2"}     # Landsat 9's instruments
_LANDSAT = re.compile(r"(?P<sensor>L[COTEM])(?P<mission>\d{2})_(?P<level>L[12][A-Z]{2})_"
                      r"(?P<path>\d{3})(?P<row>\d{3})_(?P<acquired>\d{8})_(?P<processed>\d{8})_"
                      r"(?P<collection>\d{2})_(?P<tier>T1|T2|RT)"
                      r"(?:_(?P<band>(?:SR_|ST_)?B\d{1,2}|QA_[A-Z]+(?:_[A-Z]+)*))?(?=[._]|$)")
_SENTINEL2_TILE = re.compile(r"T(?P<tile>\d{2}[A-Z]{3})_(?P<acquired>\d{8}T\d{6})_(?P<band>B\d[\dA]|TCI|AOT|WVP|SCL)"
                             r"(?:_(?P<resolution>\d+m))?(?=[._]|$)")
_SENTINEL2_SAFE = re.compile(r"(?P<unit>S2[A-D])_MSI(?P<level>L1C|L2A)_(?P<acquired>\d{8}T\d{6})_N\d{4}_R\d{3}_"
                             r"T(?P<tile>\d{2}[A-Z]{3})_\d{8}T\d{6}(?:\.SAFE)?$")


@dataclass(frozen=True)
class Acquisition:
    """One measured input: a file's band, measured with ``settings``.

    Attributes
    ----------
    acquisition_id : str
        Stable identity: a digest of the file's SHA-256, the band and the
        measuring settings, so that measuring the same file again with the
        same settings gives the same id (and replaces its rows in a store).
    path : str
        The file as given.
    sha256 : str
        The file's SHA-256 (hex).
    acquired_utc : str or None
        When the scene was taken, UTC, ISO 8601 (``2021-11-21T08:15:02Z``,
        or a date, ``2021-11-21``, when only the date is known); None when
        nothing says.
    platform, instrument, band_name, level : str or None
        ``Landsat 9``, ``OLI-2``, ``B8``, ``L1TP``..., None when not known.
    gsd_m : float or None
        Pixel size in metres when the file is georeferenced.
    band : int, str or None
        The band measured (1-based; None: the single band or luminance).
    product_id : str or None
        The standard product's name (Landsat product id, Sentinel-2 granule).
    site : str or None
        Where on the ground the product's grid puts it (``WRS-2 181/040``,
        ``MGRS 32TNR``).
    settings : dict
        The measuring settings (JSON-able).
    sources : dict
        Where each fact came from: ``option``, ``metadata``, ``product name``
        or ``TIFF tag``.
    overview : str or None
        A figure of the whole scene (a scan's ``overview.png``), which the
        campaign report shows beside the acquisition.
    imgmtf_version, run_utc : str
        Provenance of the run.
    sensor_key : str or None
        What identifies the file's sensor when no platform is named
        (:func:`sensor_key`): the camera's make, model and serial number
        when the file is tagged with them, else the image's size, data
        type, bands, GSD and the software that wrote it.  The campaign's
        trends group unnamed platforms by it, so that two sensors are
        never trended together.

    Examples
    --------
    >>> from imgmtf.campaign.acquisitions import Acquisition
    >>> a = Acquisition("a1", "scene.tif", "00", "2024-05-01", platform="SYNTHSAT-1", gsd_m=2.0)
    >>> a.platform, a.acquired_utc, a.band
    ('SYNTHSAT-1', '2024-05-01', None)
    """

    acquisition_id: str
    path: str
    sha256: str
    acquired_utc: str | None = None
    platform: str | None = None
    instrument: str | None = None
    band_name: str | None = None
    gsd_m: float | None = None
    level: str | None = None
    product_id: str | None = None
    site: str | None = None
    band: int | str | None = None
    settings: dict = field(default_factory=dict)
    sources: dict = field(default_factory=dict)
    overview: str | None = None
    imgmtf_version: str = __version__
    run_utc: str = ""
    sensor_key: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """The acquisition as a JSON-ready dict (settings and sources as mappings)."""
        return json_safe(asdict(self))


def acquisition_id(sha256: str, band: int | str | None, settings: dict) -> str:
    """The stable identity of a file's band measured with ``settings``: the
    first 16 hex digits of the SHA-256 of all three (settings as sorted JSON).

    Examples
    --------
    >>> acquisition_id("ab" * 32, 1, {"method": "ESF"})
    'b922266771bf3903'
    """
    text = json.dumps({"sha256": sha256, "band": band, "settings": json_safe(settings)}, sort_keys=True,
                      default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def file_sha256(path: str | Path) -> str:
    """The SHA-256 of a file's bytes (hex).

    Raises
    ------
    ImageReadError
        The file cannot be read.
    """
    try:
        with open(path, "rb") as fh:
            return hashlib.file_digest(fh, "sha256").hexdigest()
    except OSError as exc:
        raise ImageReadError(f"{path}: cannot read: {exc.strerror or exc}") from None


def parse_time(text: str, what: str = "time") -> str:
    """An ISO 8601 date or date and time as UTC text: ``2021-11-21`` stays a
    date, a time becomes ``YYYY-MM-DDTHH:MM:SSZ`` (converted to UTC when it
    carries an offset, taken as UTC when it has none).  Also reads the TIFF
    tag's ``YYYY:MM:DD HH:MM:SS``.

    Raises
    ------
    ParameterError
        ``text`` is not such a date or time (the message names ``what``).

    Examples
    --------
    >>> parse_time("2021-11-21"), parse_time("2025-06-19T12:15:59+02:00"), parse_time("2020:01:02 03:04:05")
    ('2021-11-21', '2025-06-19T10:15:59Z', '2020-01-02T03:04:05Z')
    """
    value = str(text).strip()
    tiff = re.fullmatch(r"(\d{4}):(\d{2}):(\d{2})[ T](\d{2}:\d{2}:\d{2})", value)
    if tiff:
        value = f"{tiff[1]}-{tiff[2]}-{tiff[3]}T{tiff[4]}"
    if re.fullmatch(r"\d{4}-\d{2}-\d{2}", value):
        try:
            datetime.strptime(value, "%Y-%m-%d")
        except ValueError:
            raise ParameterError(f"{what} {text!r} is not a valid date (YYYY-MM-DD)") from None
        return value
    try:
        moment = datetime.fromisoformat(value)
    except ValueError:
        raise ParameterError(f"{what} {text!r} is not an ISO 8601 date or time "
                             "(e.g. 2021-11-21 or 2021-11-21T08:15:02Z)") from None
    if moment.tzinfo is not None:
        moment = moment.astimezone(UTC)
    return moment.strftime("%Y-%m-%dT%H:%M:%SZ")


def _compact_time(text: str) -> str:
    """``20250619T101559`` or ``20211121`` as ISO 8601 (UTC)."""
    if "T" in text:
        return datetime.strptime(text, "%Y%m%dT%H%M%S").strftime("%Y-%m-%dT%H:%M:%SZ")
    return datetime.strptime(text, "%Y%m%d").strftime("%Y-%m-%d")


def parse_product_name(path: str | Path) -> dict[str, str]:
    """The facts a standard product name states: ``platform``,
    ``instrument``, ``acquired_utc``, ``band_name``, ``level``,
    ``product_id`` and ``site``, from the file's name or, for Sentinel-2,
    the ``.SAFE`` folder it lies in; an empty dict for any other name.

    Examples
    --------
    >>> facts = parse_product_name("LC09_L1TP_181040_20211121_20211122_02_T1_B8.TIF")
    >>> facts["platform"], facts["instrument"], facts["acquired_utc"], facts["site"], facts["band_name"]
    ('Landsat 9', 'OLI-2', '2021-11-21', 'WRS-2 181/040', 'B8')
    >>> facts = parse_product_name("T32TNR_20250619T101559_B04_10m.jp2")
    >>> facts["platform"], facts["acquired_utc"], facts["site"], facts["band_name"], facts["level"]
    ('Sentinel-2', '2025-06-19T10:15:59Z', 'MGRS 32TNR', 'B04', 'L2A')
    """
    path = Path(path)
    name = path.name
    landsat = _LANDSAT.search(name)
    if landsat:
        return _landsat_facts(landsat)
    facts: dict[str, str] = {}
    tile = _SENTINEL2_TILE.search(name)
    if tile:
        facts = {"platform": "Sentinel-2", "instrument": "MSI", "acquired_utc": _compact_time(tile["acquired"]),
                 "band_name": tile["band"], "site": f"MGRS {tile['tile']}",
                 "product_id": f"T{tile['tile']}_{tile['acquired']}"}
        if tile["resolution"]:          # only Level-2A names carry the resolution
            facts["level"] = "L2A"
    for part in (path, *path.parents):
        safe = _SENTINEL2_SAFE.search(part.name)
        if safe:
            facts.update({"platform": f"Sentinel-{safe['unit'][1:]}", "instrument": "MSI",
                          "acquired_utc": _compact_time(safe["acquired"]), "level": safe["level"],
                          "site": f"MGRS {safe['tile']}", "product_id": safe[0].removesuffix(".SAFE")})
            break
    return facts


def _landsat_facts(match: re.Match) -> dict[str, str]:
    mission = int(match["mission"])
    band = match["band"]
    instrument = _LANDSAT_SENSORS[match["sensor"][1]]
    if match["sensor"] == "LC" and band and re.fullmatch(r"(ST_)?B1[01]", band):
        instrument = "TIRS"         # a combined OLI/TIRS product's thermal bands
    if mission >= 9:
        instrument = _LANDSAT_SECOND_GENERATION.get(instrument, instrument)
    product = match[0] if not band else match[0][: -len(band) - 1]
    facts = {"platform": f"Landsat {mission}", "instrument": instrument,
             "acquired_utc": _compact_time(match["acquired"]), "level": match["level"],
             "site": f"WRS-2 {match['path']}/{match['row']}", "product_id": product}
    if band:
        facts["band_name"] = band
    return facts


# tags that name the camera itself (TIFF and EXIF, as GDAL reports them), in the order the key lists them
_CAMERA_TAGS = (("TIFFTAG_MAKE", "EXIF_Make"), ("TIFFTAG_MODEL", "EXIF_Model"),
                ("EXIF_BodySerialNumber", "EXIF_CameraSerialNumber"))


def sensor_key(info: RasterInfo, metadata: dict[str, dict[str, str]]) -> str:
    """What identifies the sensor of a file that names no platform.

    The camera's make, model and serial number when the file's TIFF or
    EXIF tags give them; otherwise the image's signature: its size (px),
    data type, number of bands, GSD (m) and the software tag.  Files of
    one sensor cut or written alike share it; files that differ in any
    of these are never taken for one sensor.

    Parameters
    ----------
    info : imgmtf.io.RasterInfo
        The file's header (:func:`imgmtf.io.raster_info`).
    metadata : dict
        Its metadata by domain (:func:`imgmtf.io.raster_metadata`).

    Returns
    -------
    str
        E.g. ``camera Canon EOS 5D`` or ``101 x 101 px uint16``.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.io import raster_info, raster_metadata
    >>> imgmtf.write_geotiff("chip.tif", imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 64).image)
    >>> sensor_key(raster_info("chip.tif"), raster_metadata("chip.tif"))
    '64 x 64 px uint16, GSD 1 m'
    """
    default = metadata.get("default", {})
    camera = [next((default[t].strip() for t in tags if default.get(t, "").strip()), "") for tags in _CAMERA_TAGS]
    if camera[0] or camera[1]:
        return "camera " + " ".join(part for part in camera if part)
    parts = [f"{info.width} x {info.height} px {info.dtype}"]
    if info.count > 1:
        parts.append(f"{info.count} bands")
    if info.gsd_m:
        parts.append(f"GSD {info.gsd_m:g} m")
    software = default.get("TIFFTAG_SOFTWARE", "").strip()
    if software:
        parts.append(software)
    return ", ".join(parts)


def read_acquisition(path: str | Path, *, band: int | str | None = None, settings: dict | None = None,
                     acquired: str | None = None, platform: str | None = None, instrument: str | None = None,
                     band_name: str | None = None, level: str | None = None,
                     run_utc: str | None = None) -> Acquisition:
    """The acquisition of ``path`` (its ``band``) measured with ``settings``.

    Parameters
    ----------
    path : str or pathlib.Path
        The image file.
    band : int, str or None
        The band measured (1-based), as the measurement names it.
    settings : dict, optional
        The measuring settings (JSON-able): part of the acquisition's identity.
    acquired : str, optional
        When the scene was taken (ISO 8601; a time without an offset is UTC).
    platform, instrument, band_name, level : str, optional
        Facts to use instead of what the file and its name say.
    run_utc : str, optional
        The start of the run (default: now).

    Returns
    -------
    Acquisition
        With the facts found (None where nothing says) and, in ``sources``,
        where each came from.

    Raises
    ------
    ImageReadError
        The file cannot be read.
    ParameterError
        ``acquired`` is not an ISO 8601 date or time.

    Examples
    --------
    >>> import imgmtf
    >>> imgmtf.write_geotiff("LC09_L1TP_181040_20211121_20211122_02_T1_B8.TIF",
    ...                      imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 64).image, gsd_m=15.0)
    >>> a = read_acquisition("LC09_L1TP_181040_20211121_20211122_02_T1_B8.TIF", band=1)
    >>> a.platform, a.instrument, a.acquired_utc, a.band_name, a.gsd_m, a.sources["acquired_utc"]
    ('Landsat 9', 'OLI-2', '2021-11-21', 'B8', 15.0, 'product name')
    """
    from ..io import raster_info, raster_metadata

    path = str(path)
    settings = dict(json_safe(settings or {}))
    options = {"acquired_utc": parse_time(acquired, "acquired") if acquired is not None else None,
               "platform": platform, "instrument": instrument, "band_name": band_name, "level": level}
    info = raster_info(path)
    metadata = raster_metadata(path, band if isinstance(band, int) else None)
    found = _metadata_facts(metadata)
    named = parse_product_name(path)
    facts: dict[str, Any] = {}
    sources: dict[str, str] = {}
    for key in (*FACTS, "product_id", "site"):
        for source, values in (("option", options), ("metadata", found), ("product name", named)):
            if values.get(key) not in (None, ""):
                facts[key], sources[key] = values[key], source
                break
    if sources.get("acquired_utc") == "metadata":       # parsed only when it is the time used
        try:
            facts["acquired_utc"] = parse_time(facts["acquired_utc"], f"{path}: the metadata's acquisition time")
        except ParameterError as exc:
            raise ImageReadError(f"{exc}; give the acquisition time instead", reason="metadata") from None
    if "acquired_utc" not in facts and metadata["default"].get("TIFFTAG_DATETIME"):
        try:
            facts["acquired_utc"] = parse_time(metadata["default"]["TIFFTAG_DATETIME"])
            sources["acquired_utc"] = "TIFF tag"
        except ParameterError:
            pass        # a malformed tag says nothing; the other facts stand
    sha = file_sha256(path)
    return Acquisition(acquisition_id(sha, band, settings), path, sha, gsd_m=info.gsd_m, band=band,
                       settings=settings, sources=sources, run_utc=run_utc or utc_now(),
                       sensor_key=sensor_key(info, metadata), **facts)


def _metadata_facts(metadata: dict[str, dict[str, str]]) -> dict[str, str]:
    """The facts a file's metadata items state (the time as written)."""
    default, imagery = metadata["default"], metadata["imagery"]
    facts = {key: default[item].strip() for key, item in METADATA_ITEMS.items() if default.get(item, "").strip()}
    if "acquired_utc" not in facts and imagery.get("ACQUISITIONDATETIME"):
        facts["acquired_utc"] = imagery["ACQUISITIONDATETIME"]
    if "platform" not in facts and imagery.get("SATELLITEID"):
        facts["platform"] = imagery["SATELLITEID"]
    if "band_name" not in facts and metadata["band"].get("DESCRIPTION"):
        facts["band_name"] = metadata["band"]["DESCRIPTION"]
    return facts

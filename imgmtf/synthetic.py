"""A synthetic calibration campaign on disk: one GeoTIFF per acquisition
with the tags a product's reader looks for, and the truth beside them.

Each scene (:class:`imgmtf.sensor.series.SyntheticCampaign`) is written
with the metadata items ``ACQUISITION_DATETIME`` (ISO 8601 UTC),
``PLATFORM``, ``INSTRUMENT`` and ``BAND_NAME`` in the default domain, and
its provenance and truth (the sensor, the target, the exact MTF at Nyquist
across and along track, the true slope per year) in the ``IMGMTF`` tag;
``truth.json`` and ``truth.csv`` in the folder hold the same truth for
the whole campaign.
"""
from __future__ import annotations

import csv
import json
from dataclasses import asdict
from pathlib import Path

from .atomic import atomic_output, ensure_folder
from .errors import FileWriteError
from .io import write_geotiff
from .sensor.series import SyntheticCampaign
from .version import __version__

#: the columns of truth.csv, one row per acquisition
TRUTH_COLUMNS = ("file", "acquired_utc", "years", "optics_sigma_x_m", "optics_sigma_y_m",
                 "mtf_nyquist_across", "mtf_nyquist_along", "mtf50_across_cy_px", "mtf50_along_cy_px")


def write_campaign(folder: str | Path, campaign: SyntheticCampaign | None = None, *,
                   platform: str = "SYNTHSAT-1", instrument: str = "PAN", band_name: str = "PAN") -> list[Path]:
    """Render a synthetic campaign into ``folder`` (created): a GeoTIFF per
    acquisition, ``site_YYYYMMDDTHHMMSS.tif``, and ``truth.json``,
    ``truth.csv``.

    Parameters
    ----------
    folder : the output folder.
    campaign : what to render (default: six yearly acquisitions).
    platform, instrument, band_name : written in each file's tags.

    Returns
    -------
    list of pathlib.Path
        The scenes, in time order.

    Raises
    ------
    FileWriteError
        The folder or a file cannot be written.

    Examples
    --------
    >>> from imgmtf.sensor.series import SyntheticCampaign
    >>> paths = write_campaign("campaign", SyntheticCampaign(acquisitions=2, size_px=128))   # doctest: +SKIP
    >>> [p.name for p in paths]                                                              # doctest: +SKIP
    ['site_20200601T033000.tif', 'site_20210601T093000.tif']
    """
    campaign = SyntheticCampaign() if campaign is None else campaign
    out = ensure_folder(folder)
    slopes = campaign.true_slopes_per_year()
    truths, paths = [], []
    for k in range(campaign.acquisitions):
        scene = campaign.render(k)
        truth = campaign.truth(k)
        when = truth["acquired_utc"]
        path = out / f"site_{when.replace('-', '').replace(':', '').removesuffix('Z')}.tif"
        provenance = {**scene.provenance, "imgmtf_version": __version__, "gsd_m": campaign.gsd_m,
                      "target": {**asdict(scene.target), "kind": "four-quadrant"},
                      "acquired_utc": when, "truth": truth, "campaign": campaign.as_dict(),
                      "true_slope_per_year": slopes}
        write_geotiff(path, scene.image, gsd_m=campaign.gsd_m, provenance=provenance,
                      tags={"ACQUISITION_DATETIME": when, "PLATFORM": platform, "INSTRUMENT": instrument,
                            "BAND_NAME": band_name})
        truths.append({"file": path.name, **truth})
        paths.append(path)
    document = {"imgmtf_version": __version__, "campaign": campaign.as_dict(), "platform": platform,
                "instrument": instrument, "band_name": band_name,
                "sensor": "Gaussian optics (sigma across x, along y) growing by degradation_per_year of its "
                          "starting width each year, and a square pixel (detector 1 GSD wide)",
                "true_slope_per_year": {"mtf_nyquist_across": slopes["across"],
                                        "mtf_nyquist_along": slopes["along"],
                                        "note": "least-squares slope of the true values over the acquisitions"},
                "acquisitions": truths}
    _write_text(out / "truth.json", json.dumps(document, indent=1) + "\n")
    rows = [{c: t[c] for c in TRUTH_COLUMNS} for t in truths]
    with atomic_output(out / "truth.csv") as partial:
        try:
            with open(partial, "w", newline="", encoding="utf-8") as handle:
                writer = csv.DictWriter(handle, fieldnames=list(TRUTH_COLUMNS))
                writer.writeheader()
                writer.writerows(rows)
        except OSError as exc:
            raise FileWriteError(f"{out / 'truth.csv'}: cannot write: {exc.strerror or exc}") from None
    return paths


def _write_text(path: Path, text: str) -> None:
    with atomic_output(path) as partial:
        try:
            Path(partial).write_text(text, encoding="utf-8")
        except OSError as exc:
            raise FileWriteError(f"{path}: cannot write: {exc.strerror or exc}") from None

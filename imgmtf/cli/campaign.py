"""``--campaign`` and the acquisition options (``--acquired``,
``--platform``, ``--instrument``, ``--band-name``) that measure, fit and
scan share, and the writer that puts each acquisition's rows into the
store as it completes."""
from __future__ import annotations

from dataclasses import dataclass, field

import click


def _parse_acquired(ctx, param, value):
    if value is None:
        return None
    from ..campaign.acquisitions import parse_time
    from ..errors import ParameterError
    try:
        return parse_time(value, "")
    except ParameterError:
        raise click.BadParameter(f"{value!r} is not an ISO 8601 date or time (e.g. 2021-11-21 or "
                                 "2021-11-21T08:15:02Z; a time without an offset is UTC)") from None


def campaign_options(command):
    """--campaign STORE.gpkg and the acquisition's facts that override the file's."""
    for option in reversed([
        click.option("--campaign", "campaign", type=click.Path(dir_okay=False), metavar="STORE.gpkg",
                     help="add each acquisition's results to this campaign store (a GeoPackage; created if "
                          "missing; re-adding a file with the same settings replaces its rows)"),
        click.option("--acquired", callback=_parse_acquired, metavar="ISO-8601",
                     help="acquisition time (UTC unless an offset is given), for files whose metadata and "
                          "name do not say it"),
        click.option("--platform", metavar="NAME", help="platform (satellite), e.g. 'Landsat 9'"),
        click.option("--instrument", metavar="NAME", help="instrument, e.g. OLI-2"),
        click.option("--band-name", metavar="NAME", help="the band's name, e.g. B8 or pan"),
    ]):
        command = option(command)
    return command


@dataclass
class CampaignWriter:
    """Writes acquisitions into a campaign store for a command, and tells,
    once at the end, which had no acquisition time."""

    store: str
    acquired: str | None = None
    platform: str | None = None
    instrument: str | None = None
    band_name: str | None = None
    run_utc: str | None = None
    written: int = 0
    untimed: list[str] = field(default_factory=list)

    @classmethod
    def opened(cls, store: str | None, **facts) -> CampaignWriter | None:
        """The writer of ``store`` (None without one), the store created or
        checked before any work: a file that is no campaign store fails here."""
        if not store:
            return None
        from ..campaign.store import ensure_store, schema_version
        from .files import check_output_file
        check_output_file(store)
        ensure_store(store)
        schema_version(store)
        return cls(store, **facts)

    def add(self, path: str, band, settings: dict, edges=(), targets=(), overview: str | None = None):
        """One acquisition's rows written (in one transaction); its Acquisition."""
        from dataclasses import replace

        from ..campaign.acquisitions import read_acquisition
        from ..campaign.store import write_acquisition
        acquisition = read_acquisition(path, band=band, settings=settings, acquired=self.acquired,
                                       platform=self.platform, instrument=self.instrument,
                                       band_name=self.band_name, run_utc=self.run_utc)
        if overview:
            acquisition = replace(acquisition, overview=overview)
        write_acquisition(self.store, acquisition, list(edges), list(targets))
        self.written += 1
        if acquisition.acquired_utc is None:
            self.untimed.append(path)
        return acquisition

    def check_one_acquisition(self, files: list[str], band=None) -> None:
        """Refuse, before any fitting, files whose own acquisition times
        differ (a fit across acquisitions is no point of a trend), unless
        --acquired names the time."""
        from ..campaign.acquisitions import read_acquisition
        from ..errors import ParameterError
        if self.acquired or len(files) < 2:
            return
        times = {f: read_acquisition(f, band=band).acquired_utc for f in files}
        if len(set(times.values())) > 1:
            listed = ", ".join(f"{f}: {t or 'no time'}" for f, t in times.items())
            raise ParameterError(f"the files fitted are of different acquisitions ({listed}); fit each "
                                 "acquisition's chips on their own, or give --acquired")

    def add_fit(self, files: list[str], fit, settings: dict, band=None, plot: str | None = None):
        """A sensor fit of ``files``, the chips of one acquisition
        (:meth:`check_one_acquisition`), with its across- and along-track rows."""
        from ..campaign.acquisitions import file_sha256
        from ..campaign.fitted import fit_summaries
        settings = {**settings, "files": [file_sha256(f) for f in files]}
        rows = fit_summaries(fit, files[0], band, plot=plot, run_utc=self.run_utc)
        return self.add(files[0], band, settings, targets=rows)

    def summary(self) -> None:
        """What the store got, and (once) which acquisitions have no time."""
        if self.untimed:
            names = ", ".join(self.untimed[:3]) + (f" and {len(self.untimed) - 3} more" if len(self.untimed) > 3
                                                    else "")
            click.echo(f"imgmtf: note: {len(self.untimed)} acquisition(s) with no acquisition time ({names}): "
                       "neither metadata nor file name says it; they are stored but left out of trends "
                       "(give --acquired)", err=True)
        click.echo(f"{self.written} acquisition(s) written to {self.store}", err=True)

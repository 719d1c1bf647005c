"""Option types, parsing callbacks and the option groups several commands
share (kept free of numerical imports: ``imgmtf --help`` reads them)."""
from __future__ import annotations

import math

import click

from ..kinds import kinds_with_width

MAX_WORKERS = 64                    # as imgmtf.parallel.MAX_WORKERS, without importing it for --help
MIN_REPLICATES, MAX_REPLICATES = 20, 5000     # as imgmtf.estimate.intervals checks them
DEFAULT_METHOD = "msg"              # a registered resampling method (tests/test_cli.py checks)


class FiniteFloat(click.FloatRange):
    """A float option that refuses NaN and infinities (FloatRange lets NaN
    through every bound)."""

    name = "number"

    def _describe_range(self) -> str:
        """The bounds for the help ("finite" when there are none, rather
        than click's "x<=None")."""
        return "finite" if self.min is None and self.max is None else super()._describe_range()

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        return number


class RequirementType(click.ParamType):
    """--requirement: the lowest acceptable MTF at Nyquist, for every
    direction (``0.1``) or per direction (``across=0.12,along=0.10``)."""

    name = "requirement"

    def convert(self, value, param, ctx):
        from ..campaign.trend import Requirement
        from ..errors import ParameterError
        if isinstance(value, Requirement):
            return value
        try:
            return Requirement.parse(value)
        except ParameterError as exc:
            self.fail(str(exc), param, ctx)


class Replicates(click.IntRange):
    """--bootstrap N: 0 (no intervals) or MIN_REPLICATES to MAX_REPLICATES."""

    name = "integer"

    def __init__(self):
        super().__init__(0, MAX_REPLICATES)

    def _describe_range(self) -> str:
        return f"0 or {MIN_REPLICATES}<=x<={MAX_REPLICATES}"

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if 0 < number < MIN_REPLICATES:
            self.fail(f"{number} is not in the range {self._describe_range()} (fewer than {MIN_REPLICATES} "
                      "replicates give no interval worth quoting)", param, ctx)
        return number


class MethodName(click.ParamType):
    """A resampling method name, checked against the method registry when
    the option is given (the registry imports NumPy: ``imgmtf --help`` does
    not pay for it, nor a command run with the default method before it
    starts its workers)."""

    name = "method"

    @staticmethod
    def names() -> list[str]:
        from ..estimate.resampling import METHODS
        return list(METHODS)

    def get_metavar(self, param, ctx=None) -> str:
        return "[" + "|".join(self.names()) + "]"

    def convert(self, value, param, ctx):
        if value == DEFAULT_METHOD or value in self.names():
            return value
        self.fail(f"{value!r} is not one of {', '.join(map(repr, self.names()))}", param, ctx)

    def shell_complete(self, ctx, param, incomplete):
        from click.shell_completion import CompletionItem
        return [CompletionItem(n) for n in self.names() if n.startswith(incomplete)]


class MethodOption(click.Option):
    """``--method``: its help lists what each registered method does, read
    from the registry when the help is shown (not at start-up)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("type", MethodName())
        kwargs.setdefault("default", DEFAULT_METHOD)
        kwargs.setdefault("show_default", True)
        super().__init__(*args, **kwargs)

    def get_help_record(self, ctx):
        from ..estimate.resampling import METHODS
        self.help = ("how the profile's samples are smoothed and resampled before the MTF (each "
                     "method's own blur is divided out): "
                     + "; ".join(f"{m.name}: {m.description}" for m in METHODS.values()))
        return super().get_help_record(ctx)


def length_option(default_unit: str):
    """Click callback: "1.4", "1.4px" or "18.3m" -> (value, unit), the value
    finite (:func:`imgmtf.inputs.parse_length`, which the API uses too)."""
    def parse(ctx, param, value):
        if value is None:
            return None
        from ..errors import ParameterError
        from ..inputs import parse_length
        try:
            return parse_length(value, default_unit)
        except ParameterError as exc:
            raise click.BadParameter(str(exc)) from None
    return parse


def width_refusal() -> str:
    """Why ``--pulse-width`` is refused beside a ``--target`` without a
    width: it applies to the kinds of target that have one."""
    wide = " or ".join(f"--target {kind.name}" for kind in kinds_with_width())
    return f"--pulse-width applies to {wide} only"


def parse_pair(ctx, param, value):
    """Click callback: "LO,HI" -> (lo, hi), two finite numbers, lo < hi."""
    if value is None:
        return None
    try:
        low, high = (float(v) for v in value.split(","))
    except ValueError:
        raise click.BadParameter(f"expected LO,HI (two numbers), got {value!r}") from None
    if not (math.isfinite(low) and math.isfinite(high) and low < high):
        raise click.BadParameter(f"expected finite LO < HI, got {value!r}")
    return low, high


def parse_roi(ctx, param, value):
    if value is None:
        return None
    try:
        parts = tuple(int(p) for p in value.split(","))
    except ValueError:
        parts = ()
    if len(parts) != 4:
        raise click.BadParameter(f"expected X,Y,W,H (four integers), got {value!r}")
    from ..inputs import MIN_SIZE_PX
    if parts[2] < MIN_SIZE_PX or parts[3] < MIN_SIZE_PX or parts[0] < 0 or parts[1] < 0:
        raise click.BadParameter(f"expected X, Y >= 0 and W, H >= {MIN_SIZE_PX} px (the smallest chip "
                                 f"measured), got {value!r}")
    return parts


def parse_rois(ctx, param, values):
    """Click callback of a repeated --roi: a tuple of (x, y, w, h), each
    checked as :func:`parse_roi` checks one."""
    return tuple(parse_roi(ctx, param, v) for v in values or ())


def roi_file_option(command):
    """--roi-file: the polygons or lines of a vector layer as ROIs, shared
    by measure, scan and fit (the same words in each one's help)."""
    return click.option("--roi-file", type=click.Path(), metavar="FILE",
                        help="ROIs from a vector layer (shapefile, GeoJSON, GeoPackage, KML...: any format GDAL "
                             "reads): each polygon's bounds, or each line widened by 12 px either side, "
                             "reprojected onto the image; one measurement per feature, its attributes in the "
                             "record")(command)


def parse_optical_centre(ctx, param, value):
    """Click callback: "X,Y" (px) or "centre" (:func:`imgmtf.estimate.field.parse_centre`)."""
    if value is None:
        return None
    from ..errors import ParameterError
    from ..estimate.field import parse_centre
    try:
        return parse_centre(value)
    except ParameterError as exc:
        raise click.BadParameter(str(exc)) from None


def optical_centre_option(command):
    """--optical-centre: sagittal and meridional edges, shared by measure and scan."""
    return click.option("--optical-centre", callback=parse_optical_centre, metavar="X,Y|centre",
                        help="a lens's optical centre, px (pixel centres at integers), or 'centre' for the "
                             "image's: each edge is said sagittal or meridional (its normal across or along "
                             "the radius from it, as MTF Mapper reports them) with its distance from it")(command)


def read_roi_file(path: str | None):
    """The features of --roi-file (None without it), read once before any
    image: a missing or unreadable file, or a layer without a CRS, is an
    input's error (exit 1, one line naming the file)."""
    if path is None:
        return None
    from ..vectors import VectorROIs
    return VectorROIs.read(path)


def parse_band(ctx, param, value):
    if value is None or value.lower() == "all":
        return value and "all"
    try:
        band = int(value)
    except ValueError:
        raise click.BadParameter(f"expected a 1-based band number or 'all', got {value!r}") from None
    if band < 1:
        raise click.BadParameter(f"bands are numbered from 1, got {value!r}")
    return band


class WorkerCount(click.ParamType):
    """--workers N (1 to ``MAX_WORKERS``) or ``auto`` (None: the command
    chooses from the work and the cores it may use)."""

    name = "N|auto"

    def convert(self, value, param, ctx):
        if value is None or (isinstance(value, str) and value.strip().lower() == "auto"):
            return None
        try:
            number = int(value)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is neither 'auto' nor a number of workers (1 to {MAX_WORKERS})", param, ctx)
        return click.IntRange(1, MAX_WORKERS).convert(number, param, ctx)


def parallel_options(command, *, auto: bool = False):
    """--workers and --scheduler, shared by the batch commands; ``auto``:
    --workers defaults to ``auto`` (None), the command's choice."""
    command = click.option("--scheduler", metavar="ADDRESS",
                           help="run on a Dask distributed cluster (tcp://host:8786), or 'local' "
                                "for a local Dask cluster of --workers processes; needs imgmtf[dask]")(command)
    if auto:
        return click.option("--workers", type=WorkerCount(), default="auto", show_default=True,
                            help="parallel worker processes, each on one thread; auto: the cores this process "
                                 "may use when the work is large enough to pay for them, else none")(command)
    return click.option("--workers", type=click.IntRange(1, MAX_WORKERS), default=1, show_default=True,
                        help="parallel worker processes, each on one thread")(command)


def auto_parallel_options(command):
    """:func:`parallel_options` with --workers ``auto`` by default."""
    return parallel_options(command, auto=True)


def reading_options(command):
    """--saturation and --transfer: how a file's values are read, shared by
    measure and fit (the same words in each one's help)."""
    command = click.option("--transfer", default="linear", show_default=True, metavar="linear|srgb|gamma:G",
                           help="how the stored values relate to light: linearised before measuring (srgb: the "
                                "sRGB curve, gamma:2.2 a power law; 8-bit camera images are usually sRGB)")(command)
    return click.option("--saturation", callback=parse_pair, metavar="LO,HI",
                        help="DN range the sensor records (default: an integer file's type range); "
                             "sides at or beyond it are saturated")(command)


def interval_options(command):
    """--intervals, --bootstrap and --confidence, shared by measure and scan."""
    command = click.option("--confidence", type=FiniteFloat(0, 1, min_open=True, max_open=True),
                           default=0.95, show_default=True, help="confidence of the intervals")(command)
    command = click.option("--bootstrap", "replicates", type=Replicates(), metavar="N",
                           help="intervals from a bootstrap of N row resamplings (slower); "
                                "0: no intervals")(command)
    return click.option("--intervals", "interval_method", type=click.Choice(["influence", "bootstrap", "none"]),
                        show_default="influence",
                        help="confidence intervals: linearised row influence (about the cost of one fit), "
                             "a bootstrap over rows, or none")(command)


def interval_settings(method: str | None, replicates: int | None, confidence: float):
    """The interval settings the options ask for: --bootstrap N means a
    bootstrap of N replicates (0: none); an --intervals that says otherwise
    is a usage error, not silently overruled."""
    from ..estimate.intervals import Intervals
    if replicates is not None:
        implied = "bootstrap" if replicates else "none"
        if method not in (None, implied):
            raise click.UsageError(f"--bootstrap {replicates} asks for {implied} intervals, "
                                   f"--intervals {method} for others: give one")
        method = implied
    return Intervals(method or "influence", confidence, **({"replicates": replicates} if replicates else {}))

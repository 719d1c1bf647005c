"""``imgmtf simulate``: render an edge or bar chip through the sensor, or
(``--campaign DIR``) a series of calibration-site scenes through a sensor
that degrades at a known rate, with the truth beside them.

The campaign is an option of ``simulate`` rather than a command of its own:
it is what ``simulate`` does (render scenes of known MTF to files), and the
command list's column keeps every short help on one line (a name as long as
``simulate-campaign`` would wrap them).  Options that make one chip are
refused beside ``--campaign``, and the campaign's without it."""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import click

from ..errors import ParameterError
from ..kinds import get_kind, kind_names
from .errors import option_errors, reported_errors
from .files import check_output_file, load_sensor
from .options import FiniteFloat, length_option, width_refusal

# Bounds of the size-like options (see docs): what a run may allocate.
DEFAULT_LEVELS_DN = {16: (200.0, 1200.0), 8: (30.0, 210.0)}    # simulate's dark and bright sides
MAX_CHIP_PX = 4096                  # simulate --size: the renderer's 16 Mpx
MAX_OVERSAMPLING = 100              # simulate --oversampling


#: the options that describe one chip, and those that describe a campaign: each refused with the other
CHIP_ONLY = ("kind", "angle", "low", "high", "pulse_width", "offset", "noise_std", "ground_noise", "oversampling",
             "sensor_path", "out", "point_size", "spacing", "gap", "cycles", "star_profile")
#: the options of a line target (an edge or a bar) that an array of points has no use for, and the reverse
LINE_ONLY = ("angle", "pulse_width", "offset", "ground_noise", "oversampling", "gap")
POINTS_ONLY = ("point_size", "spacing")
STAR_ONLY = ("cycles", "star_profile")
STAR_SIZE_PX = 201                  # a star chip's side unless --size says otherwise
CAMPAIGN_ONLY = ("acquisitions", "start", "interval_days", "degradation", "snr", "fill", "platform", "instrument",
                 "band_name", "blur")
CAMPAIGN_SIZE_PX = 320              # a campaign scene's side unless --size says otherwise


@click.command(short_help="Render an edge, bar, point or star chip through the sensor.")
@click.option("--target", "kind", type=click.Choice(kind_names()), default="edge", show_default=True)
@click.option("--angle", type=FiniteFloat(-90, 90, min_open=True), default=6.0, show_default=True,
              help="angle of the edge's normal from the x (column) axis, degrees in (-90, 90], which "
                   "is the edge's tilt from vertical: near 0 across track, near 90 along track "
                   "(measure reports it as normal_angle_deg)")
@click.option("--low", type=FiniteFloat(), show_default="200 at 16 bits, 30 at 8",
              help="DN on the dark side (outside a pulse)")
@click.option("--high", type=FiniteFloat(), show_default="1200 at 16 bits, 210 at 8",
              help="DN on the bright side (inside a pulse)")
@click.option("--pulse-width", callback=length_option("px"),
              help="bar width of a pulse target, at least 0.2 px and at most --size: 1.5 or 1.5px (pixels), "
                   "1.5m (metres on the ground)")
@click.option("--gap", callback=length_option("px"),
              help="--target double-bar: the gap between its two bars, edge to edge: 2 or 2px (pixels), 2m "
                   "(metres on the ground); --pulse-width each bar's width")
@click.option("--point-size", type=FiniteFloat(0, 20), default=0.0, show_default=True,
              help="--target points: each target's side, px (0: points of light; 1: Rauchmiller's 1 px squares)")
@click.option("--spacing", type=FiniteFloat(2, 1000), default=12.0, show_default=True,
              help="--target points: distance between the 4 x 4 targets' centres, px (each at its own quarter-pixel "
                   "offset)")
@click.option("--cycles", type=click.IntRange(4, 2000),
              help="--target star: periods around the centre (default: the outermost ring at about 0.125 cy/px, "
                   "0.075 for a binary star, whose wedges' levels are read there)")
@click.option("--star-profile", type=click.Choice(["sinusoidal", "binary"]), default="sinusoidal", show_default=True,
              help="--target star: ISO 12233's sinusoidal star (s-SFR) or black and white wedges")
@click.option("--offset", type=FiniteFloat(), default=0.0, show_default=True,
              help="sub-pixel position of the edge along its normal from the chip centre, px")
@click.option("--size", type=click.IntRange(2, MAX_CHIP_PX), default=50,
              show_default="50; 201 for a star; 320 with --campaign",
              help="chip (or campaign scene) side, pixels")
@click.option("--gsd", type=FiniteFloat(0, min_open=True), help="output GSD in metres (default: the sensor's)")
@click.option("--bits", type=click.Choice(["8", "16"]), default="16", show_default=True)
@click.option("--noise-std", type=FiniteFloat(0), default=0.0, show_default=True, help="system noise std, DN")
@click.option("--ground-noise", is_flag=True, help="add the paper's 20-layer ground noise (2000 DN^2)")
@click.option("--oversampling", type=click.IntRange(1, MAX_OVERSAMPLING), default=20, show_default=True,
              help="sub-pixels per pixel")
@click.option("--sensor", "sensor_path", type=click.Path(dir_okay=False), help="sensor TOML file")
@click.option("--seed", type=click.IntRange(min=0), help="random seed for the noise (an integer >= 0)")
@click.option("--out", type=click.Path(dir_okay=False),
              help="output file: .tif (a GeoTIFF that records the GSD and how the chip was made) "
                   "or .png (pixels only)")
@click.option("--campaign", "campaign_dir", type=click.Path(file_okay=False),
              help="instead of a chip: a calibration campaign in this folder, one Baotou-like scene per "
                   "acquisition through a sensor whose optics blur more each year, and its truth")
@click.option("--acquisitions", type=click.IntRange(2, 1000), default=6, show_default=True,
              help="campaign: how many scenes, one per acquisition date")
@click.option("--start", default="2020-06-01T03:30:00Z", show_default=True,
              help="campaign: the first acquisition's time, ISO 8601 UTC")
@click.option("--interval", "interval_days", type=FiniteFloat(0, min_open=True), default=365.0, show_default=True,
              help="campaign: days between acquisitions")
@click.option("--degradation", type=FiniteFloat(0, 10), default=0.06, show_default=True,
              help="campaign: the optics' blur grows by this fraction of its starting width each year")
@click.option("--snr", type=FiniteFloat(0, min_open=True), default=180.0, show_default=True,
              help="campaign: the smallest step between the target's quadrants over the noise")
@click.option("--fill", is_flag=True,
              help="campaign: every pixel outside the target 0, as in an L0R chip (its inner half-edges only)")
@click.option("--blur", type=click.Choice(["gaussian", "l0r"]), default="gaussian", show_default=True,
              help="campaign: the sensor's blur: Gaussian optics and a pixel, or a real L0R sensor's (a small "
                   "Gaussian core, exponential wings, a scatter halo and a one-sided lag along track)")
@click.option("--platform", default="SYNTHSAT-1", show_default=True, help="campaign: PLATFORM tag of every scene")
@click.option("--instrument", default="PAN", show_default=True, help="campaign: INSTRUMENT tag")
@click.option("--band-name", default="PAN", show_default=True, help="campaign: BAND_NAME tag")
@click.pass_context
def simulate(ctx, kind, angle, low, high, pulse_width, gap, point_size, spacing, cycles, star_profile, offset, size,
             gsd, bits, noise_std,
             ground_noise, oversampling, sensor_path, seed, out, campaign_dir, acquisitions, start, interval_days,
             degradation, snr, fill, blur, platform, instrument, band_name):
    """Render an edge or pulse chip through the generic sensor to a GeoTIFF
    (or a PNG); or, with --campaign DIR, a calibration campaign:
    DIR/site_<time>.tif, one scene per acquisition (a four-quadrant target
    tilted 16.8 deg on a uniform field; anisotropic Gaussian optics, or with
    --blur l0r a real L0R sensor's blur, and a square pixel, the blur
    growing each year), each tagged
    ACQUISITION_DATETIME, PLATFORM, INSTRUMENT and BAND_NAME, and
    DIR/truth.json and truth.csv: each acquisition's exact MTF at Nyquist
    across and along track, and the true slope per year."""
    given = {name for name in ctx.params if ctx.get_parameter_source(name) != click.core.ParameterSource.DEFAULT}
    if campaign_dir is not None:
        clash = [name for name in CHIP_ONLY if name in given]
        if clash:
            raise click.UsageError(f"{_flag(ctx, clash[0])} makes a single chip: not with --campaign")
        with reported_errors():
            _campaign(campaign_dir, acquisitions, start, interval_days, degradation,
                      size if "size" in given else CAMPAIGN_SIZE_PX, snr, int(bits), seed or 0, gsd, fill,
                      blur, platform, instrument, band_name)
        return
    clash = [name for name in CAMPAIGN_ONLY if name in given]
    if clash:
        raise click.UsageError(f"{_flag(ctx, clash[0])} describes a campaign: give --campaign DIR")
    if out is None:
        raise click.UsageError("give --out FILE (a chip) or --campaign DIR (a series of scenes)")
    with reported_errors():
        default_low, default_high = DEFAULT_LEVELS_DN[int(bits)]     # a step that fits the bit depth
        low = default_low if low is None else low
        high = default_high if high is None else high
        from ..io import write_geotiff, write_png
        from ..sensor.noise import GroundNoise
        from ..sensor.rendering import render
        from ..sensor.targets import Target
        suffix = Path(out).suffix.lower()
        if suffix not in (".tif", ".tiff", ".png"):
            raise click.BadParameter(f"{out}: simulate writes a GeoTIFF (.tif, .tiff), which records the GSD and "
                                     "how the chip was made, or a PNG (.png, pixels only); "
                                     f"got {suffix or 'no suffix'}", param_hint="'--out'")
        target_kind = get_kind(kind)
        drawn_apart = target_kind.renderer is not None       # no line: its own renderer (points, stars)
        own = DRAWN_APART[target_kind.renderer][1] if drawn_apart else ()
        refused = (LINE_ONLY + POINTS_ONLY + STAR_ONLY) if drawn_apart else POINTS_ONLY + STAR_ONLY
        clash = [name for name in refused if name in given and name not in own]
        if clash:
            raise click.UsageError(f"{_flag(ctx, clash[0])} does not apply to --target {kind}")
        if drawn_apart:
            check_output_file(out)
            maker, _, default_size = DRAWN_APART[target_kind.renderer]
            maker(target_kind, out, suffix, load_sensor(sensor_path), gsd, size if "size" in given else default_size,
                  int(bits), low, high, noise_std, seed, **{name: ctx.params[name] for name in own})
            return
        if target_kind.has_width and pulse_width is None:
            raise click.UsageError(f"a {kind} target needs --pulse-width (1.5 or 1.5px: pixels; 1.5m: metres)")
        if not target_kind.has_width and pulse_width is not None:
            raise click.UsageError(width_refusal())
        if (target_kind.gap_keyword is not None) != (gap is not None):
            raise click.UsageError(f"a {kind} target needs --gap (2 or 2px: pixels; 2m: metres)"
                                   if gap is None else f"--gap applies to --target double-bar only, not to a {kind}")
        check_output_file(out)
        sensor = load_sensor(sensor_path)
        gsd_m = sensor.gsd_m if gsd is None else gsd
        # simulate reads no input: a value the renderer refuses is a bad option (exit 2)
        with option_errors():
            width_px = 0.0
            if target_kind.has_width:
                value, unit = pulse_width
                width_px = value if unit == "px" else value / gsd_m
                from ..inputs import MIN_BAR_WIDTH_PX
                if not width_px >= MIN_BAR_WIDTH_PX:
                    raise ParameterError(f"--pulse-width: a {width_px:g} px wide pulse is narrower than the "
                                         f"{MIN_BAR_WIDTH_PX} px imgmtf can measure (is the unit right?)")
                if width_px > size:
                    raise ParameterError(f"--pulse-width ({width_px:g} px) is wider than the chip "
                                         f"(--size {size} px)")
            gap_px = 0.0 if gap is None else (gap[0] if gap[1] == "px" else gap[0] / gsd_m)
            target = Target(kind, angle, low, high, offset, width_px, gap_px)
            chip = render(sensor, target, size, gsd_m=gsd_m, oversampling=oversampling, bits=int(bits),
                          noise_std_dn=noise_std, ground_noise=GroundNoise() if ground_noise else None,
                          seed=seed)
        if suffix == ".png":
            write_png(out, chip.image)
        else:
            write_geotiff(out, chip.image, gsd_m=chip.gsd_m, provenance=chip.provenance())
        clipped = f", {100 * chip.clipped_fraction:.1f} % of pixels clipped" if chip.clipped_fraction else ""
        width = f" {width_px:g} px wide" if target_kind.has_width else ""
        width += f", {gap_px:g} px apart" if gap is not None else ""
        click.echo(f"wrote {out}: {size} x {size} px, {bits}-bit, {kind}{width} at {angle:g} deg, "
                   f"GSD {chip.gsd_m:g} m; true MTF at Nyquist along the normal "
                   f"{float(chip.true_mtf(0.5)):.4f}{clipped}")
        if suffix == ".png":
            click.echo(f"note: a PNG keeps the pixels only; the GSD and how the chip was made (which "
                       f"`measure` uses to draw the true MTF) are kept in a GeoTIFF: --out "
                       f"{Path(out).with_suffix('.tif')}")


def _points_chip(kind, out, suffix, sensor, gsd, size, bits, low, high, noise_std, seed, *, point_size, spacing):
    """A 4 x 4 array of point targets (squares of ``point_size`` px) at
    quarter-pixel offsets, rendered exactly; the truth across and along
    track in the file's tags."""
    from ..io import write_geotiff, write_png
    from ..sensor.points import PointArray
    gsd_m = sensor.gsd_m if gsd is None else gsd
    with option_errors():
        array = PointArray(4, 4, spacing_px=spacing, size_px=point_size, low_dn=low, high_dn=high)
        chip = kind.load("renderer")(sensor, array, size, gsd_m=gsd_m, bits=bits, noise_std_dn=noise_std, seed=seed)
    provenance = chip.provenance()
    truth = {"TRUE_MTF_NYQUIST_ACROSS": f"{provenance['mtf_nyquist_across']:.6f}",
             "TRUE_MTF_NYQUIST_ALONG": f"{provenance['mtf_nyquist_along']:.6f}",
             "TARGET_SIZE_PX": f"{point_size:g}"}
    if suffix == ".png":
        write_png(out, chip.image)
    else:
        write_geotiff(out, chip.image, gsd_m=chip.gsd_m, provenance=provenance, tags=truth)
    what = f"{point_size:g} px squares" if point_size else "points"
    clipped = f", {100 * chip.clipped_fraction:.1f} % of pixels clipped" if chip.clipped_fraction else ""
    click.echo(f"wrote {out}: {size} x {size} px, {bits}-bit, 4 x 4 {what} {spacing:g} px apart at quarter-pixel "
               f"offsets, GSD {chip.gsd_m:g} m; true MTF at Nyquist across track "
               f"{provenance['mtf_nyquist_across']:.4f}, along track {provenance['mtf_nyquist_along']:.4f}{clipped}")


def _star_chip(kind, out, suffix, sensor, gsd, size, bits, low, high, noise_std, seed, *, cycles, star_profile):
    """A Siemens star filling the chip, rendered exactly; the truth across
    and along track in the file's tags."""
    from ..io import write_geotiff, write_png
    from ..sensor.star import SiemensStar, default_cycles
    gsd_m = sensor.gsd_m if gsd is None else gsd
    with option_errors():
        profile = star_profile
        n = default_cycles(size, profile) if cycles is None else cycles
        star = SiemensStar(cycles=n, profile=profile, low_dn=low, high_dn=high)
        chip = kind.load("renderer")(sensor, star, size, gsd_m=gsd_m, bits=bits, noise_std_dn=noise_std, seed=seed)
    provenance = chip.provenance()
    truth = {"TRUE_MTF_NYQUIST_ACROSS": f"{provenance['mtf_nyquist_across']:.6f}",
             "TRUE_MTF_NYQUIST_ALONG": f"{provenance['mtf_nyquist_along']:.6f}",
             "TRUE_MTF50_ACROSS_CY_PX": f"{chip.true_mtf50_cy_px(0.0):.6f}",
             "TRUE_MTF50_ALONG_CY_PX": f"{chip.true_mtf50_cy_px(90.0):.6f}",
             "STAR_CYCLES": str(n), "STAR_PROFILE": profile}
    if suffix == ".png":
        write_png(out, chip.image)
    else:
        write_geotiff(out, chip.image, gsd_m=chip.gsd_m, provenance=provenance, tags=truth)
    clipped = f", {100 * chip.clipped_fraction:.1f} % of pixels clipped" if chip.clipped_fraction else ""
    click.echo(f"wrote {out}: {size} x {size} px, {bits}-bit, {profile} Siemens star of {n} cycles (Nyquist at "
               f"r = {star.nyquist_radius_px:.1f} px), GSD {chip.gsd_m:g} m; true MTF at Nyquist across track "
               f"{provenance['mtf_nyquist_across']:.4f}, along track {provenance['mtf_nyquist_along']:.4f}{clipped}")


#: the chips of kinds drawn apart from lines, by their renderer: how each is made, the options it takes and its
#: side unless --size says otherwise
DRAWN_APART: dict[str, tuple[Callable[..., None], tuple[str, ...], int]] = {
    "imgmtf.sensor.points:render_points": (_points_chip, POINTS_ONLY, 50),
    "imgmtf.sensor.star:render_star": (_star_chip, STAR_ONLY, STAR_SIZE_PX)}


def _flag(ctx, name: str) -> str:
    """The command-line flag of a parameter."""
    return next(p.opts[0] for p in ctx.command.params if p.name == name)


def _campaign(folder, acquisitions, start, interval_days, degradation, size_px, snr, bits, seed, gsd, fill,
              blur, platform, instrument, band_name) -> None:
    from ..sensor.series import SyntheticCampaign
    from ..synthetic import write_campaign
    campaign = SyntheticCampaign(acquisitions, start, interval_days, degradation, snr=snr, size_px=size_px,
                                 bits=bits, seed=seed, gsd_m=1.0 if gsd is None else gsd, fill=fill, blur=blur)
    paths = write_campaign(folder, campaign, platform=platform, instrument=instrument, band_name=band_name)
    click.echo(f"{'scene':<28} {'acquired (UTC)':<21} {'true MTF@Nyq across':>19} {'along':>7}")
    for k, path in enumerate(paths):
        truth = campaign.truth(k)
        click.echo(f"{path.name:<28} {truth['acquired_utc']:<21} {truth['mtf_nyquist_across']:19.4f} "
                   f"{truth['mtf_nyquist_along']:7.4f}")
    slopes = campaign.true_slopes_per_year()
    click.echo(f"true slope per year: across {slopes['across']:+.4f}, along {slopes['along']:+.4f} "
               "(least squares over the acquisitions)")
    click.echo(f"wrote {len(paths)} scenes ({size_px} x {size_px} px, {bits}-bit, SNR {snr:g}), "
               f"truth.json and truth.csv to {folder}")

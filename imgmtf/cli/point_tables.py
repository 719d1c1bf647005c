"""The text ``imgmtf scan --target points`` prints: one row per point array
and direction, the rejected arrays with their reasons, the scene's rows."""
from __future__ import annotations

import click

from .hints import rejection_hint
from .tables import SHORT_DIRECTIONS, interval_cell, num_cell, plural, snr_cell, warning_text


def print_point_scan(scene, info, records, summaries, written, fmt) -> None:
    """A scene's point arrays: per accepted array and direction its MTF at
    Nyquist, interval, MTF50, FWHM and points used; a line per rejected
    array; the scene's rows (``*`` on the one to quote); then the files
    written.  JSON Lines with ``fmt`` "json"."""
    if fmt == "json":
        import sys

        from ..records import to_json, write_whole
        write_whole(sys.stdout, "".join(to_json(r) + "\n" for r in (*records, *summaries)))
        return
    arrays = {r.site.get("target_id") for r in records}
    accepted = {r.site.get("target_id") for r in records if r.ok}
    click.echo(f"{scene}: {info.width} x {info.height} px, {plural(len(arrays), 'point array')}, "
               f"{len(accepted)} accepted")
    if accepted:
        click.echo(f"{'id':>4} {'arr':>3} {'dir':>7} {'pts':>7} {'SNR':>5} {'MTF@Nyq':>7} {'interval':>17} "
                   f"{'MTF50':>7} {'FWHM':>6} {'alias':>5}  ROI x,y,w,h")
        click.echo(f"{'':>4} {'':>3} {'':>7} {'used/fd':>7} {'':>5} {'':>7} {'':>17} {'cy/px':>7} {'px':>6}")
    for record in records:
        r = record.to_dict()
        if not record.ok:
            continue
        direction = SHORT_DIRECTIONS.get(r.get("direction"), r.get("direction") or "-")
        used = f"{r.get('points_used')}/{r.get('points_found')}"
        click.echo(f"{r['id']:>4} {r['target_id']:>3} {direction:>7} {used:>7} {snr_cell(r.get('snr'))} "
                   f"{num_cell(r.get('mtf_nyquist'), 7, 4)} {interval_cell(r.get('mtf_nyquist_ci')):>17} "
                   f"{num_cell(r.get('mtf50_cy_px'), 7, 4)} {num_cell(r.get('fwhm_px'), 6, 3)} "
                   f"{num_cell(r.get('alias_weight'), 5, 2)}  {','.join(str(v) for v in r['roi'])}")
        for warning in r.get("warnings") or []:
            click.echo(warning_text(" " * 10, warning, hint=False))
    for record in records:
        if not record.ok:
            r = record.to_dict()
            message = r["error"].removeprefix(r["path"] + ": ")
            # the scan's peaks grouped into the array, not the features its measurement then finds in the ROI
            click.echo(f"array {r['target_id']} at ({r['x_px']:.0f}, {r['y_px']:.0f}), grouped from "
                       f"{plural(r['points_found'], 'peak')} the scan found: rejected, {r['reason']}: {message}"
                       f"{rejection_hint(r['reason'], message)}")
    if summaries:
        click.echo("the scene per direction, its arrays combined by precision (* the row to quote):")
        for summary in summaries:
            r = summary.to_dict()
            mark = "*" if r.get("recommended") else " "
            click.echo(f"{mark}{SHORT_DIRECTIONS.get(r['direction'], r['direction']):>7} {r['n_arrays']:>3} arrays "
                       f"{r['points_used']:>4} points  MTF@Nyq {num_cell(r['mtf_nyquist'], 7, 4)} "
                       f"{interval_cell(r['mtf_nyquist_ci'])}  MTF50 {num_cell(r.get('mtf50_cy_px'), 7, 4)} cy/px  "
                       f"FWHM {num_cell(r.get('fwhm_px'), 6, 3)} px")
    for path in written:
        click.echo(f"wrote {path}")

"""The calibration campaign end to end, against its exact truth.

1. ``imgmtf simulate --campaign DIR``: six yearly Baotou-like scenes
   (320 x 320 px, a four-quadrant target tilted 16.8 deg on a uniform
   field, anisotropic Gaussian optics and a square pixel, the optics 6 %
   wider each year, SNR 180), each tagged with its time, platform and
   band, and DIR/truth.json; then the same with ``--blur l0r``: a real
   L0R sensor's blur (a small Gaussian core, exponential wings per axis,
   a scatter halo and a one-sided lag along track over the pixel; MTF at
   Nyquist 0.06-0.17), which the Gaussian model cannot fit.
2. ``imgmtf scan SCENE --campaign STORE --acquired T --platform P
   --band-name B`` once per scene (a process each, as a user adds each
   acquisition when it arrives).
3. ``imgmtf report STORE --out DIR``: the trend of every figure.

Printed, against the done-when figures of the campaign issue:

* per acquisition, the recommended across- and along-track rows' MTF at
  Nyquist (the fit's, or where a store names none, the fit rows) against
  the truth: every error within 0.006 (Gaussian) or 0.010 (L0R), no row
  flagged misfit, the intervals covering the truth in at least 10 of the
  12;
* the recommended series' slopes per year (trend.csv) over the true slopes
  (least squares over the true values): within 0.6 to 1.4, and flagged as
  drift;
* the combined rows beside them (along the targets' oblique normals: they
  are not across- or along-track figures, so no truth applies);
* the time of each scan;
* then the real Baotou and PAN L0R chips (../shared/data/real-scenes;
  their README says what is known) through ``scan --campaign`` and
  ``report``, their fit rows with the default stages and with others.

usage: python bench/campaign.py [--keep DIR] [--seed N]
"""
from __future__ import annotations

import argparse
import csv
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REAL = Path(__file__).resolve().parent.parent.parent / "shared" / "data" / "real-scenes"
# the real chips, with the time each is given (Baotou's from its source's file name; PAN's is not known)
REAL_CHIPS = {"baotou_l0r_checkerboard.tif": "2020-03-28T03:23:32Z", "pan_l0r_checkerboard.tif": "2020-01-01"}
OTHER_STAGES = ("optics,detector", "optics,detector,diffusion,halo,lag")
#: each campaign's blur and the largest error at Nyquist its done-when allows
BLURS = {"gaussian": 0.006, "l0r": 0.010}


def imgmtf(*args: str) -> subprocess.CompletedProcess:
    run = subprocess.run([sys.executable, "-m", "imgmtf.cli", *args], capture_output=True, text=True)
    if run.returncode not in (0, 1):
        raise SystemExit(f"imgmtf {' '.join(args)} failed ({run.returncode}):\n{run.stderr}")
    return run


def store_rows(store: Path, layer: str) -> list[dict]:
    from imgmtf.campaign.store import read_layer
    return read_layer(store, layer)


def recommended(rows: list[dict], axis: str) -> list[dict]:
    """The rows of one direction a store recommends (the fit's where it names none)."""
    mine = [r for r in rows if r["direction"] == f"{axis}-track" and r["method"] in ("fit", "sections")]
    if any(r.get("recommended") is not None for r in mine):
        return [r for r in mine if r.get("recommended")]
    return [r for r in mine if r["method"] == "fit"]


def synthetic(work: Path, seed: int, blur: str) -> bool:
    tolerance = BLURS[blur]
    scenes, store, report = work / f"scenes-{blur}", work / f"site-{blur}.gpkg", work / f"report-{blur}"
    imgmtf("simulate", "--campaign", str(scenes), "--seed", str(seed), "--blur", blur)
    truth = json.loads((scenes / "truth.json").read_text())
    times = []
    for acquisition in truth["acquisitions"]:
        start = time.perf_counter()
        imgmtf("scan", str(scenes / acquisition["file"]), "--campaign", str(store), "--acquired",
               acquisition["acquired_utc"], "--platform", truth["platform"], "--band-name", truth["band_name"],
               "--no-progress")
        times.append(time.perf_counter() - start)
    targets = store_rows(store, "targets")
    print(f"\nsynthetic campaign, {blur} blur: {len(truth['acquisitions'])} scenes, seed {seed}; "
          f"scan --campaign per scene {min(times):.1f}-{max(times):.1f} s (a process each, start-up included)")
    print(f"{'acquired':<21} {'dir':<7} {'truth':>7} {'row':>7} {'error':>8} {'interval':>17} {'covers':>6} "
          f"{'misfit':>6} method   combined along the oblique normals")
    errors, covered, n, misfits = [], 0, 0, 0
    for acquisition in truth["acquisitions"]:
        mine = [r for r in targets if r["acquired_utc"] == acquisition["acquired_utc"] and r["scope"] == "target"]
        combined = " ".join(f"{r['normal_angle_deg']:.1f} deg {r['mtf_nyquist']:.4f}"
                            for r in mine if r["method"] == "combined")
        for axis in ("across", "along"):
            rows = recommended(mine, axis)
            truth_value = acquisition[f"mtf_nyquist_{axis}"]
            if len(rows) != 1:
                print(f"{acquisition['acquired_utc']:<21} {axis:<7} {truth_value:7.4f} {len(rows)} recommended rows")
                errors.append(float("inf"))
                n += 1
                continue
            row = rows[0]
            error = row["mtf_nyquist"] - truth_value
            low, high = row["mtf_nyquist_ci_low"], row["mtf_nyquist_ci_high"]
            inside = low <= truth_value <= high
            misfit = bool(json.loads(row["record"]).get("misfit"))
            errors.append(abs(error))
            covered += inside
            misfits += misfit
            n += 1
            print(f"{acquisition['acquired_utc']:<21} {axis:<7} {truth_value:7.4f} {row['mtf_nyquist']:7.4f} "
                  f"{error:+8.4f} {f'[{low:.4f},{high:.4f}]':>17} {'yes' if inside else 'NO':>6} "
                  f"{'yes' if misfit else 'no':>6} {row['method']:<8} {combined if axis == 'across' else ''}")
    worst = max(errors)
    accuracy_ok, coverage_ok = worst <= tolerance and misfits == 0, covered >= 10 and n == 12
    print(f"largest error {worst:.4f}, {misfits} misfit rows (done when <= {tolerance} and none: "
          f"{'PASS' if accuracy_ok else 'FAIL'}); intervals "
          f"cover the truth in {covered} of {n} (done when >= 10 of 12: {'PASS' if coverage_ok else 'FAIL'})")

    run = imgmtf("report", str(store), "--out", str(report))
    if run.returncode:
        print(f"report failed: {run.stderr.strip()}")
        return False
    trend = list(csv.DictReader((report / "trend.csv").open()))
    slopes_ok = True
    for axis in ("across", "along"):
        true_slope = truth["true_slope_per_year"][f"mtf_nyquist_{axis}"]
        # the series the report quotes for this direction (recommended, never misfit), whatever its method
        rows = [r for r in trend if r["figure"] == "mtf_nyquist" and r["direction"] == f"{axis}-track"
                and r.get("recommended") == "True" and r.get("misfit") != "True" and r["slope_per_year"]]
        if not rows:
            print(f"  {axis}: no recommended {axis}-track trend in trend.csv")
            slopes_ok = False
            continue
        row = max(rows, key=lambda r: int(r["n_acquisitions"]))
        how = row["method"] + (f" ({row['assumption']})" if row.get("assumption") else "")
        slope, ratio = float(row["slope_per_year"]), float(row["slope_per_year"]) / true_slope
        drift = row["drift"] in ("True", "true", "1")
        ok = 0.6 <= ratio <= 1.4 and drift
        slopes_ok &= ok
        print(f"trend, {how} {axis}-track MTF at Nyquist: {slope:+.5f} per year "
              f"[{float(row['slope_ci_low']):+.5f}, {float(row['slope_ci_high']):+.5f}], true {true_slope:+.5f}: "
              f"ratio {ratio:.3f} (done when 0.6-1.4 and flagged), drift {drift}: {'PASS' if ok else 'FAIL'}")
    oblique = [r for r in trend if r["figure"] == "mtf_nyquist" and r["method"] == "combined" and r["slope_per_year"]]
    for row in oblique:
        print(f"trend, combined ({row['direction']}) MTF at Nyquist: {float(row['slope_per_year']):+.5f} per year")
    print(f"report: {report / 'report.html'}")
    return accuracy_ok and coverage_ok and slopes_ok


def real(work: Path) -> None:
    if not REAL.is_dir():
        print(f"no real scenes in {REAL}: skipped")
        return
    store, report = work / "real.gpkg", work / "real-report"
    for name, acquired in REAL_CHIPS.items():
        # no --platform: the report keys each unnamed chip by its file (two sensors, never one trend)
        imgmtf("scan", str(REAL / name), "--campaign", str(store), "--acquired", acquired, "--no-progress")
    run = imgmtf("report", str(store), "--out", str(report))
    print(f"\nreal chips through scan --campaign and report (exit {run.returncode}; {report / 'report.html'}):")
    print(f"{'chip':<28} {'method':<22} {'dir':<13} {'normal':>7} {'MTF@Nyq':>7} {'interval':>17} {'MTF50':>7} "
          f"{'FWHM':>6} misfit quoted")
    for row in store_rows(store, "targets"):
        if row["scope"] != "target":
            continue
        record = json.loads(row["record"])
        interval = f"[{row['mtf_nyquist_ci_low']:.4f},{row['mtf_nyquist_ci_high']:.4f}]"
        method = row["method"] + (f" ({row['assumption']})" if row.get("assumption") else "")
        print(f"{Path(record['path']).name:<28} {method:<22} {row['direction']:<13} "
              f"{row['normal_angle_deg'] or float('nan'):7.2f} {row['mtf_nyquist'] or float('nan'):7.4f} "
              f"{interval:>17} {row['mtf50_cy_px'] or float('nan'):7.4f} {row['fwhm_px'] or float('nan'):6.3f} "
              f"{str(record.get('misfit', '')) if row['method'] == 'fit' else '':>6} "
              f"{'yes' if row.get('recommended') else ''}")
    for stages in OTHER_STAGES:
        for name in REAL_CHIPS:
            run = imgmtf("scan", str(REAL / name), "--fit-stages", stages, "--format", "json", "--no-progress")
            for line in run.stdout.splitlines():
                row = json.loads(line)
                if row.get("summary") == "fit" and row.get("scope") == "target":
                    print(f"{name:<28} fit with {stages}: {row['direction']:<13} MTF@Nyq {row['mtf_nyquist']:.4f} "
                          f"MTF50 {row['mtf50_cy_px']:.4f} misfit {row['misfit']} (p {row['misfit_p']:.2g})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--keep", type=Path, help="work in this folder and keep it (default: a temporary one)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        work = args.keep or Path(scratch)
        work.mkdir(parents=True, exist_ok=True)
        ok = all([synthetic(work, args.seed, blur) for blur in BLURS])
        real(work)
    print(f"\ncampaign done-when figures: {'PASS' if ok else 'FAIL'}")


if __name__ == "__main__":
    main()

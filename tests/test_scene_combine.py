"""Combining half-edges: precision weights, disagreement, direction families."""
import dataclasses
import math

import numpy as np
import pytest
from scipy.special import ndtri, stdtrit

from imgmtf.records import Record
from imgmtf.scene.combine import combine, normal_families, summarise_scan


def interval(value, sd, rows, confidence=0.95):
    half = stdtrit(rows - 1, 0.5 + confidence / 2) * sd
    return value - half, value + half


def test_weights_are_inverse_variances_and_the_interval_shrinks_as_one_over_root_sum():
    values, sds, rows = [0.26, 0.28], [0.01, 0.02], [30, 60]
    c = combine(values, [interval(v, s, n) for v, s, n in zip(values, sds, rows)], rows)
    w = np.array([1 / 0.01 ** 2, 1 / 0.02 ** 2])
    assert c.value == pytest.approx(np.sum(w * values) / w.sum())
    chi2 = float(np.sum(w * (np.array(values) - c.value) ** 2))
    assert c.consistency == pytest.approx(math.sqrt(chi2))              # n - 1 = 1 degree of freedom
    assert c.consistency < 1 and c.weights == "inverse-variance"
    assert (c.high - c.low) / 2 == pytest.approx(ndtri(0.975) / math.sqrt(w.sum()))


def test_disagreeing_estimates_widen_the_interval_by_the_birge_ratio():
    values, sd = [0.20, 0.30, 0.25], 0.005
    c = combine(values, [interval(v, sd, 40) for v in values], [40] * 3)
    assert c.value == pytest.approx(0.25) and c.consistency == pytest.approx(10.0)
    assert (c.high - c.low) / 2 == pytest.approx(ndtri(0.975) * sd / math.sqrt(3) * 10.0)


def test_one_estimate_keeps_its_own_interval():
    c = combine([0.26], [(0.25, 0.27)], [40])
    assert (c.value, c.low, c.high, c.weights) == (0.26, 0.25, 0.27, "inverse-variance")


def test_without_intervals_the_mean_is_plain_and_has_none():
    c = combine([0.2, 0.3, float("nan")], [(float("nan"),) * 2] * 3, [40] * 3)
    assert c.value == pytest.approx(0.25) and math.isnan(c.low) and c.weights == "equal"
    with pytest.raises(ValueError):
        combine([float("nan")], [(0.1, 0.2)], [40])


@pytest.mark.parametrize("normals, families", [
    ([16.8, -73.2, 17.1, 106.9, 45.0], [0, 1, 0, 1, 2]),
    ([89.0, -88.0, 1.0, -2.0], [0, 0, 1, 1]),                 # 89 and -88 are 3 deg apart, across the wrap
    ([0.0, 8.0, 16.0, 24.0, 32.0], [0, 0, 0, 1, 1]),          # no family spans more than 20 deg
])
def test_normals_group_into_direction_families(normals, families):
    assert normal_families(normals).tolist() == families


def edge(id_, normal, mtf, sd, target, x=0.0):
    return Record("s.tif", 1, "edge", "msg", "accepted",
                  figures={"normal_angle_deg": normal, "mtf_nyquist": mtf, "mtf_nyquist_ci": interval(mtf, sd, 30),
                           "mtf50_cy_px": 0.3, "mtf50_ci_cy_px": interval(0.3, 0.003, 30), "rows_used": 30,
                           "fwhm_px": 1.2 + 0.1 * id_, "snr": 100.0 * id_, "gsd_m": None},
                  site={"id": id_, "target_id": target, "x0_px": x, "y0_px": 0.0, "x1_px": x + 2, "y1_px": 40.0},
                  params={"intervals": {"confidence": 0.95}, "track_azimuth_deg": 0.0})


def test_one_summary_per_target_and_direction_and_per_scene():
    records = [edge(1, 5.0, 0.26, 0.01, 1), edge(2, -85.0, 0.24, 0.01, 1, 50), edge(3, 4.0, 0.28, 0.01, 1, 100),
               edge(4, 6.0, 0.27, 0.02, 2, 300)]
    rejected = Record("s.tif", 1, "edge", "msg", "rejected", "fill", "s.tif: fill", site={"id": 5})
    out = summarise_scan([*records, rejected])
    keys = [(r.site["scope"], r.site.get("target_id"), r.figures["direction"], r.figures["n_edges"]) for r in out]
    assert keys == [("target", 1, "across-track", 2), ("target", 1, "along-track", 1),
                    ("target", 2, "across-track", 1), ("scene", None, "across-track", 3),
                    ("scene", None, "along-track", 1)]
    first = out[0]
    assert first.status == "combined" and first.ok and first.figures["edge_ids"] == [1, 3]
    assert first.figures["mtf_nyquist"] == pytest.approx(0.27) and first.site["x_px"] == pytest.approx(51.0)
    assert out[3].figures["mtf_nyquist"] == pytest.approx((0.26 + 0.28 + 0.27 / 4) / 2.25)
    # FWHM weighted as the MTF at Nyquist is; the lowest SNR of the half-edges
    assert first.figures["fwhm_px"] == pytest.approx(1.4) and first.figures["snr_min"] == 100.0
    assert out[3].figures["fwhm_px"] == pytest.approx((1.3 + 1.5 + 1.6 / 4) / 2.25)
    assert first.figures["rer"] is None and "fwhm_m" not in first.figures      # none given, no GSD


def test_the_summary_curve_weights_each_curve_as_its_nyquist_interval_earns():
    def with_curve(record, curve):
        return dataclasses.replace(record, figures={**record.figures, "frequencies_cy_px": [0.0, 0.25, 0.5],
                                                    "mtf": curve})

    weighted = [with_curve(edge(1, 5.0, 0.5, 0.01, 1), [1.0, 0.5, None]),      # a bar's masked frequency
                with_curve(edge(2, 6.0, 0.3, 0.02, 1), [1.0, 0.3, 0.2])]
    summary = summarise_scan(weighted)[0]
    assert summary.figures["frequencies_cy_px"] == [0.0, 0.25, 0.5]
    assert summary.figures["mtf"] == pytest.approx([1.0, (4 * 0.5 + 0.3) / 5, 0.2])   # a masked value leaves the other
    plain = [dataclasses.replace(r, figures={**r.figures, "mtf_nyquist_ci": [None, None]}) for r in weighted]
    assert summarise_scan(plain)[0].figures["mtf"][1] == pytest.approx(0.4)     # no intervals: equal weights


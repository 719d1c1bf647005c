"""A scan's across/along rows without a model: the sections of every
target's combined directions, and the one row per direction to quote."""
import numpy as np
import pytest

from imgmtf.cli.tables import print_recommended, print_sections
from imgmtf.errors import ParameterError
from imgmtf.records import Record
from imgmtf.scene.sections import recommend, section_rows, sensor_frame

F = np.round(np.linspace(0.0, 1.0, 101), 2)


def truth(u, v):
    """Square pixel and an anisotropic Gaussian: separable and elliptical."""
    return np.sinc(u) * np.sinc(v) * np.exp(-2 * np.pi ** 2 * (0.35 ** 2 * u ** 2 + 0.45 ** 2 * v ** 2))


def combined(normal_deg, scope="target", target=1, track=0.0, half_width=0.01):
    a = np.radians(normal_deg - track)
    curve = truth(F * np.cos(a), F * np.sin(a))
    nyquist = float(curve[50])
    site = {"scope": scope, **({"target_id": target, "x_px": 50.0, "y_px": 50.0} if scope == "target" else {})}
    return Record("scene.tif", 1, "edge", "msg", "combined", site=site,
                  figures={"summary": "combined", "direction": "oblique", "normal_angle_deg": normal_deg,
                           "n_edges": 2, "edge_ids": [1, 3], "mtf_nyquist": nyquist,
                           "mtf_nyquist_ci": [nyquist - half_width, nyquist + half_width], "rows_used": 60,
                           "snr_min": 80.0, "gsd_m": None, "frequencies_cy_px": F.tolist(), "mtf": curve.tolist()},
                  params={"intervals": {"confidence": 0.95}, "track_azimuth_deg": track})


def fit(direction, value, misfit, scope="target", target=1):
    site = {"scope": scope, **({"target_id": target} if scope == "target" else {})}
    return Record("scene.tif", 1, "edge", "msg", "fitted", site=site,
                  figures={"summary": "fit", "direction": direction, "mtf_nyquist": value,
                           "mtf_nyquist_ci": [value - 0.004, value + 0.004], "misfit": misfit})


def test_two_directions_give_each_assumption_and_their_bracket_across_and_along():
    rows = section_rows([combined(16.8), combined(-73.2), combined(16.8, "scene"), combined(-73.2, "scene")])
    assert [(r.site["scope"], r.figures["assumption"], r.figures["direction"]) for r in rows[:6]] == [
        ("target", a, d) for a in ("separable", "elliptical", "bracket") for d in ("across-track", "along-track")]
    assert len(rows) == 12 and {r.site["scope"] for r in rows[6:]} == {"scene"}
    for r in rows:
        f = r.figures
        exact = truth(0.5, 0.0) if f["direction"] == "across-track" else truth(0.0, 0.5)
        assert r.status == "combined" and f["summary"] == "sections" and f["chosen_assumption"] == "bracket"
        assert abs(f["mtf_nyquist"] - exact) < 0.005
        assert f["mtf_nyquist_ci"][0] < exact < f["mtf_nyquist_ci"][1]
        assert f["mtf50_ci_cy_px"][0] <= f["mtf50_cy_px"] <= f["mtf50_ci_cy_px"][1]
        assert f["normal_angle_deg"] == (0.0 if f["direction"] == "across-track" else 90.0)
        assert f["n_edges"] == 4 and len(f["mtf"]) == len(f["frequencies_cy_px"])
    assert rows[0].site == {"scope": "target", "target_id": 1, "x_px": 50.0, "y_px": 50.0}


def test_the_track_turns_across_and_along():
    # rows across the image's columns: across track is the image's y
    rows = section_rows([combined(16.8, track=90.0), combined(-73.2, track=90.0)])
    across = next(r for r in rows if r.figures["direction"] == "across-track")
    assert across.figures["normal_angle_deg"] == 90.0
    assert abs(across.figures["mtf_nyquist"] - truth(0.5, 0.0)) < 0.005
    assert sensor_frame(106.8, 90.0) == pytest.approx(16.8)


def test_one_direction_or_no_track_gives_no_sections():
    assert section_rows([combined(16.8), combined(20.0)]) == []
    no_track = combined(-73.2).with_(params={"track_azimuth_deg": None})
    assert section_rows([combined(16.8).with_(params={"track_azimuth_deg": None}), no_track]) == []
    with pytest.raises(ParameterError, match="summary Records"):
        section_rows(["not a record"])


def quoted(rows):
    return {(r.site["scope"], r.figures["direction"]): (r.figures["summary"], r.figures.get("assumption"))
            for r in rows if r.figures.get("recommended")}


def test_one_row_per_direction_is_recommended_and_never_a_misfit():
    sections = section_rows([combined(16.8), combined(-73.2)])
    across, along = truth(0.5, 0.0), truth(0.0, 0.5)
    # a fit that fits and agrees with the sections: the fit
    rows = recommend([*sections, fit("across-track", across, False), fit("along-track", along, False)])
    assert quoted(rows) == {("target", "across-track"): ("fit", None), ("target", "along-track"): ("fit", None)}
    assert all(r.figures["recommended_because"] for r in rows)
    # a misfit fit (however close), or one that disagrees: the sections' chosen assumption
    rows = recommend([*sections, fit("across-track", across, True), fit("along-track", along + 0.1, False)])
    assert quoted(rows) == {("target", "across-track"): ("sections", "bracket"),
                            ("target", "along-track"): ("sections", "bracket")}
    because = {r.figures["direction"]: r.figures["recommended_because"] for r in rows if r.figures["summary"] == "fit"}
    assert because == {"across-track": "the model does not fit",
                       "along-track": "it disagrees with the sections at Nyquist"}
    # without intervals (--intervals none) a fit that fits is quoted: nothing says it disagrees
    bare = [r.with_(figures={**r.figures, "mtf_nyquist_ci": [None, None]}) for r in sections]
    rows = recommend([*bare, fit("across-track", across + 0.1, False)])
    assert quoted(rows)[("target", "across-track")] == ("fit", None)
    # only misfit rows: none recommended, and the table says so
    rows = recommend([fit("across-track", 0.002, True)])
    assert quoted(rows) == {} and rows[0].figures["recommended"] is False


def test_the_table_marks_the_recommended_row_and_says_when_only_misfits_exist(capsys):
    rows = recommend([*section_rows([combined(16.8), combined(-73.2)]), fit("across-track", 0.002, True)])
    print_sections([r for r in rows if r.figures["summary"] == "sections"])
    print_recommended(rows)
    text = capsys.readouterr().out
    marked = [line for line in text.splitlines() if line.startswith("*")]
    assert len(marked) == 3 and all("bracket" in line for line in marked[:2])
    assert "bracket: two orientations cannot tell separable from elliptical" in text
    print_recommended(recommend([fit("along-track", 0.003, True)]))
    assert "target 1 along-track: only misfit fit rows, no figure to quote" in capsys.readouterr().out


def test_a_third_orientation_in_the_scene_chooses_for_the_scene():
    # two targets tilted 16.8 and 40 deg under an elliptical blur (a square pixel and an isotropic
    # exponential remainder): each target alone is a bracket, the scene's four orientations choose
    def elliptical(u, v):
        return np.sinc(u) * np.sinc(v) * np.exp(-2 * np.pi * 0.35 * np.hypot(u, v))

    def row(normal, scope, target):
        a = np.radians(normal)
        record = combined(normal, scope, target)
        curve = elliptical(F * np.cos(a), F * np.sin(a))
        nyquist = float(curve[50])
        return record.with_(figures={**record.figures, "mtf": curve.tolist(), "mtf_nyquist": nyquist,
                                     "mtf_nyquist_ci": [nyquist - 0.008, nyquist + 0.008]})

    rows = section_rows([row(16.8, "target", 1), row(-73.2, "target", 1), row(40.0, "target", 2),
                         row(-50.0, "target", 2), *(row(n, "scene", None) for n in (16.8, -73.2, 40.0, -50.0))])
    chosen = {(r.site["scope"], r.site.get("target_id")): r.figures["chosen_assumption"] for r in rows}
    assert chosen == {("target", 1): "bracket", ("target", 2): "bracket", ("scene", None): "elliptical"}
    scene = [r for r in rows if r.site["scope"] == "scene"]
    assert {r.figures["assumption"] for r in scene} == {"separable", "elliptical"}     # no bracket row
    assert "section rejects the other" in scene[0].figures["assumption_because"]
    for r in scene:
        if r.figures["assumption"] == "elliptical":
            exact = elliptical(0.5, 0.0)
            assert abs(r.figures["mtf_nyquist"] - exact) < 0.003
            assert r.figures["mtf_nyquist_ci"][0] < exact < r.figures["mtf_nyquist_ci"][1]


# the Gaussian core alone, which misfits as plainly as the default stages at a fifth of the cost (docs/scan.md's
# Baotou example runs the default, auto, and checks its printed rows)
@pytest.mark.parametrize("name, stages", [("baotou_l0r_checkerboard.tif", "optics,detector"),
                                          ("pan_l0r_checkerboard.tif", "optics,detector")])
def test_the_real_chips_quote_sections_not_their_misfit_fits(name, stages):
    from imgmtf.scene.series import scan_one
    from imgmtf.scene.settings import ScanSettings

    from conftest import real_scene
    outcome = scan_one(str(real_scene(name)), ScanSettings(track_azimuth_deg=0.0), stages)
    quoted = [r for r in outcome.summaries if r.figures.get("recommended")]
    assert sorted((r.site["scope"], r.figures["direction"]) for r in quoted) == [
        ("scene", "across-track"), ("scene", "along-track"), ("target", "across-track"), ("target", "along-track")]
    for r in quoted:
        assert r.figures["summary"] == "sections" and r.figures["assumption"] == "bracket"
        assert 0.06 < r.figures["mtf_nyquist"] < 0.2
    fits = [r for r in outcome.summaries if r.figures.get("summary") == "fit"]
    assert fits and all(r.figures["misfit"] and not r.figures["recommended"] for r in fits)


def test_the_sections_on_workers_are_the_sections_here(monkeypatch):
    """Targets sent to two workers in tasks of one (the task runner's own
    pool is tested with it; here its tasks run in turn): the same rows in
    the same order (targets by id, then the scene) as worked out here."""
    import imgmtf.parallel
    import imgmtf.scene.sections as sections
    summaries = [combined(normal, target=k) for k in (2, 1) for normal in (16.8, -73.2)]
    summaries += [combined(16.8, "scene"), combined(-73.2, "scene")]
    here = section_rows(summaries)
    asked = []

    def in_turn(function, items, workers, **options):
        asked.append((workers, len(items)))
        return map(function, items)
    monkeypatch.setattr(imgmtf.parallel, "run_tasks", in_turn)
    monkeypatch.setattr(sections, "AUTO_TARGETS_PER_WORKER", 1)
    monkeypatch.setattr(sections, "TARGETS_PER_TASK", 1)
    there = section_rows(summaries, workers=2)
    assert asked == [(2, 3)]
    assert [(r.site, r.figures) for r in there] == [(r.site, r.figures) for r in here]
    assert [r.site.get("target_id") for r in there[::6]] == [1, 2, None]
    with pytest.raises(ParameterError, match="workers"):
        section_rows(summaries, workers=0)

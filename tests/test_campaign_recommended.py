"""Which row of a store to quote per acquisition, place and direction, and
whose sensor a row measures."""
from imgmtf.campaign.recommended import mark_recommended, sensor_of


def row(method, direction="across-track", misfit=None, recommended=None, **extra):
    return {"acquisition_id": "a1", "scope": "scene", "target_id": None, "direction": direction,
            "method": method, "misfit": misfit, "recommended": recommended, **extra}


def chosen(rows):
    return [(r["method"], r["direction"]) for r in mark_recommended(rows) if r["recommended"]]


def test_an_older_stores_rows_quote_the_fit_when_it_fits_or_else_the_combined_row():
    assert chosen([row("fit", misfit=0), row("combined")]) == [("fit", "across-track")]
    assert chosen([row("fit", misfit=1), row("combined")]) == [("combined", "across-track")]
    marked = mark_recommended([row("fit", misfit=1), row("fit", "along-track", misfit=1)])
    assert not any(r["recommended"] for r in marked)                    # only misfit rows: nothing to quote
    assert all(r["recommended_because"].startswith("misfit") for r in marked)


def test_each_direction_and_oblique_normal_has_its_own_recommended_row():
    rows = [row("fit", misfit=0), row("combined", "along-track"),
            row("combined", "oblique", normal_angle_deg=16.8), row("combined", "oblique", normal_angle_deg=-73.2)]
    assert chosen(rows) == [("fit", "across-track"), ("combined", "along-track"), ("combined", "oblique"),
                            ("combined", "oblique")]


def test_a_rows_own_mark_is_kept_but_a_misfit_is_never_recommended():
    rows = [row("fit", misfit=0, recommended=0, recommended_because="the residuals prefer the sections"),
            row("sections", recommended=1, assumption="bracket", recommended_because="the data decide"),
            row("fit", "along-track", misfit=1, recommended=1)]
    marked = mark_recommended(rows)
    assert [r["recommended"] for r in marked] == [False, True, False]
    assert marked[0]["recommended_because"] == "the residuals prefer the sections"
    assert marked[2]["recommended_because"].startswith("misfit")


def test_an_unnamed_platform_is_keyed_by_its_files_or_stands_alone():
    assert sensor_of({"platform": "Landsat 9", "sensor_key": "x"}) == "Landsat 9"
    assert sensor_of({"platform": None, "sensor_key": "80 x 80 px uint16"}) == "unnamed: 80 x 80 px uint16"
    assert sensor_of({"acquisition_id": "0123456789abcdef"}) != sensor_of({"acquisition_id": "fedcba9876543210"})


def image_row(acquisition, method, value, low, high, recommended=None, assumption=None):
    return {"acquisition_id": acquisition, "scope": "scene", "target_id": None, "direction": "along-track",
            "method": method, "assumption": assumption, "mtf_nyquist": value, "mtf_nyquist_ci_low": low,
            "mtf_nyquist_ci_high": high, "recommended": recommended, "acquired_utc": "2024-01-01",
            "platform": "Sim", "band_name": "pan"}


def test_a_point_array_of_the_same_image_settles_the_edges_choice():
    edges = [image_row("e", "sections", 0.150, 0.145, 0.155, 1, "separable"),
             image_row("e", "sections", 0.132, 0.127, 0.137, 0, "elliptical")]
    points = image_row("p", "points", 0.130, 0.124, 0.136)
    marked = mark_recommended([*edges, points])
    assert [r["recommended"] for r in marked] == [False, True, True]
    assert marked[1]["recommended_because"].startswith("settled by a point array of the image")
    assert "disagrees" in marked[0]["recommended_because"]
    # agreeing: kept, and said so; another image (another time) is not judged by it
    agreeing = mark_recommended([image_row("e", "sections", 0.131, 0.126, 0.136, 1, "separable"), points])
    assert agreeing[0]["recommended"] and agreeing[0]["recommended_because"].endswith("agrees")
    elsewhere = mark_recommended([edges[0], {**points, "acquired_utc": "2024-02-01"}])
    assert elsewhere[0]["recommended"] and "point array" not in (elsewhere[0].get("recommended_because") or "")


def test_edges_that_all_disagree_with_the_point_array_keep_their_row_and_say_so():
    marked = mark_recommended([image_row("e", "fit", 0.160, 0.155, 0.165, 1),
                               image_row("p", "points", 0.130, 0.124, 0.136)])
    assert marked[0]["recommended"] and "disagrees at Nyquist" in marked[0]["recommended_because"]


def test_a_photos_image_axes_are_directions_like_the_tracks():
    # a file with no georeference is told in its own axes: its rows are one direction each, whatever their normals
    rows = [row("fit", "horizontal", misfit=0), row("combined", "horizontal", normal_angle_deg=0.6),
            row("combined", "vertical", normal_angle_deg=89.7)]
    assert chosen(rows) == [("fit", "horizontal"), ("combined", "vertical")]

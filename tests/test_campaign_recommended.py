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


def test_a_photos_image_axes_are_directions_like_the_tracks():
    # a file with no georeference is told in its own axes: its rows are one direction each, whatever their normals
    rows = [row("fit", "horizontal", misfit=0), row("combined", "horizontal", normal_angle_deg=0.6),
            row("combined", "vertical", normal_angle_deg=89.7)]
    assert chosen(rows) == [("fit", "horizontal"), ("combined", "vertical")]

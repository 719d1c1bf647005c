"""The registry of target kinds (imgmtf.kinds): lookup, its refusal of an
unknown kind, each kind's facts and parts, and the rule it exists for: no
module outside the registry compares a kind's name."""
import ast
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import imgmtf
from imgmtf.errors import ParameterError
from imgmtf.kinds import KINDS, Kind, get_kind, kind_names, kinds_with_width
from imgmtf.kinds.double_bar import DOUBLE_BAR
from imgmtf.kinds.edge import EDGE
from imgmtf.kinds.points import POINTS
from imgmtf.kinds.pulse import PULSE
from imgmtf.kinds.star import STAR
from imgmtf.records import SUMMARY_COLUMNS

PACKAGE = Path(imgmtf.__file__).parent
MAX_REGISTRY_COMPARISONS = 4


def kind_comparisons(path: Path, names: set[str]) -> list[int]:
    """The lines of ``path`` that compare a value with one of ``names``
    (==, !=, in, is, and match's case patterns)."""
    lines = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Compare):
            operands = [node.left, *node.comparators]
            values = [e for o in operands for e in (o.elts if isinstance(o, (ast.Tuple, ast.List, ast.Set)) else [o])]
            if any(isinstance(v, ast.Constant) and v.value in names for v in values):
                lines.add(node.lineno)
        elif isinstance(node, ast.MatchValue) and isinstance(node.value, ast.Constant) and node.value.value in names:
            lines.add(node.lineno)
    return sorted(lines)


def test_the_comparison_finder_finds_every_form(tmp_path):
    path = tmp_path / "probe.py"
    path.write_text('if kind == "edge":\n    pass\nok = "pulse" != kind\nok = kind in ("edge", "x")\n'
                    'match kind:\n    case "pulse":\n        pass\nok = kind == "bar"\nname = "edge"\n')
    assert kind_comparisons(path, {"edge", "pulse"}) == [1, 3, 4, 6]


def test_no_module_outside_the_registry_compares_a_kind_name():
    names = set(KINDS)
    found = {str(path.relative_to(PACKAGE)): lines for path in sorted(PACKAGE.rglob("*.py"))
             if (lines := kind_comparisons(path, names))}
    outside = {path: lines for path, lines in found.items() if not path.startswith("kinds/")}
    assert outside == {}, f"ask imgmtf.kinds.get_kind(name) for the kind's facts instead: {outside}"
    inside = sum(len(lines) for lines in found.values())
    assert inside <= MAX_REGISTRY_COMPARISONS


def test_lookup_returns_the_registered_kinds_in_order():
    assert kind_names() == ("edge", "pulse", "points", "double-bar", "star")
    assert get_kind("edge") is EDGE and get_kind("pulse") is PULSE and get_kind("points") is POINTS
    assert get_kind("star") is STAR
    assert all(KINDS[name].name == name for name in KINDS)
    assert kinds_with_width() == (PULSE, DOUBLE_BAR)


@pytest.mark.parametrize("name", ["spoke", "Edge", "", None, 3])
def test_an_unknown_kind_is_refused_naming_the_kinds_there_are(name):
    kinds = r"\('edge', 'pulse', 'points', 'double-bar', 'star'\)"
    with pytest.raises(ParameterError, match=rf"target kind must be one of {kinds}, got ") as info:
        get_kind(name)
    assert isinstance(info.value, ValueError)
    with pytest.raises(ParameterError, match=r"^target must be one of"):
        get_kind(name, "target")


def test_each_kind_names_its_parts_and_they_name_it_back():
    for kind in KINDS.values():
        result = kind.load("result")
        assert result.target == kind.name
        if kind.measuring is not None:                  # a kind of the 1-D pipeline
            assert kind.load("measuring").registered is kind
        else:                                           # a kind with its own: drawn and measured apart
            assert kind.scene_response is None and kind.renderer is not None
            with pytest.raises(ParameterError, match="has no measuring part"):
                kind.load("measuring")
        assert type(kind.make_estimator("msg")).__name__ == kind.estimator.rpartition(":")[2]
        assert set(kind.record_fields) <= set(SUMMARY_COLUMNS)
        assert kind.column.field in kind.record_fields


def test_the_facts_of_an_edge_and_of_a_bar():
    assert (EDGE.noun, EDGE.has_width, EDGE.column.heading, EDGE.column.unit) == ("edge", False, "RER", "")
    assert (PULSE.noun, PULSE.has_width, PULSE.column.heading, PULSE.column.unit) == ("bar", True, "W", "px")
    assert EDGE.fits_sensor and not PULSE.fits_sensor
    assert EDGE.lone_line is None and PULSE.lone_line == ("not-a-bar", "a lone edge, not the two sides of a bar")
    assert EDGE.masked_by is None and PULSE.masked_by == "the bar's sinc"
    assert EDGE.estimator_keywords(None) == {} and PULSE.estimator_keywords(None) == {"width_px": None}
    assert EDGE.described.format(width_px=0.0) == "edge"
    assert PULSE.profile_label.format(width_px=1.5) == "PRF, bar 1.50 px"


def test_scene_responses_are_an_edge_response_and_the_difference_of_two():
    d = np.linspace(-3.0, 3.0, 13)

    def esf(x):                 # a 2 px linear ramp
        return np.clip(0.5 + x / 2.0, 0.0, 1.0)
    assert np.array_equal(EDGE.scene_response(d, esf, 0.0), esf(d))
    bar = PULSE.scene_response(d, esf, 1.0)
    assert bar.max() == pytest.approx(0.5) and bar[0] == 0.0 and bar[-1] == 0.0      # 1 px bar, 2 px blur
    assert np.allclose(bar, bar[::-1])


def test_each_kinds_column_is_in_its_measurement():
    sensor = imgmtf.Sensor()
    for kind in KINDS.values():
        width = 1.5 if kind.has_width else 0.0
        gap = 2.0 if kind.gap_keyword else 0.0
        if kind.renderer is not None:
            from imgmtf.sensor.points import PointArray
            from imgmtf.sensor.star import SiemensStar
            target = {POINTS: PointArray(2, 2), STAR: SiemensStar(cycles=24)}[kind]
            chip = kind.load("renderer")(sensor, target, 60 if kind is POINTS else 81)
        else:
            chip = imgmtf.render(sensor, imgmtf.Target(kind.name, 6.0, width_px=width, gap_px=gap), 60)
        result = kind.make_estimator("msg", intervals=imgmtf.Intervals("none"))(
            chip.image, **kind.estimator_keywords(width or None, gap_px=gap or None))
        figures = result.to_dict(curves=False)
        assert figures["target"] == kind.name and figures[kind.column.field] is not None


def test_a_registered_kind_is_a_target_the_sensor_renders(monkeypatch):
    line = replace(PULSE, name="line", noun="line")              # one new kind, one registration
    monkeypatch.setitem(KINDS, "line", line)
    assert "line" in kind_names()
    target = imgmtf.Target("line", 6.0, 0.0, 1.0, width_px=1.0)
    d = np.array([-5.0, 0.0, 5.0])
    assert np.allclose(target.image_values(d, lambda x: (x > 0).astype(float)), [0.0, 1.0, 0.0])
    with pytest.raises(ParameterError, match="line width must be > 0 pixels"):
        imgmtf.Target("line", 6.0)


def test_the_registry_loads_nothing_numerical_and_nothing_above_it():
    code = ("import sys, imgmtf.kinds; print(sorted(m for m in sys.modules if m.startswith('imgmtf') or "
            "m in ('numpy', 'scipy', 'cv2', 'matplotlib')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert eval(out.stdout) == ["imgmtf", "imgmtf.errors", "imgmtf.kinds", "imgmtf.kinds.double_bar",
                                "imgmtf.kinds.edge", "imgmtf.kinds.kind", "imgmtf.kinds.points", "imgmtf.kinds.pulse",
                                "imgmtf.kinds.star"]


def test_the_facts_of_points():
    assert (POINTS.noun, POINTS.has_width, POINTS.column.field) == ("point", False, "points_used")
    assert POINTS.measuring is None and POINTS.scene_response is None and not POINTS.fits_sensor
    assert POINTS.estimator_keywords(None, 1.0) == {"point_size_px": 1.0}
    assert EDGE.estimator_keywords(None, 1.0) == {}
    with pytest.raises(ParameterError, match="a points target is no straight line"):
        imgmtf.Target("points")


def test_kind_is_a_frozen_record_of_facts():
    with pytest.raises(AttributeError):
        EDGE.name = "step"              # type: ignore[misc]
    assert isinstance(EDGE, Kind)


def test_the_facts_of_a_star():
    assert (STAR.noun, STAR.has_width, STAR.column.field) == ("star", False, "star_cycles")
    assert STAR.measuring is None and STAR.scene_response is None and not STAR.fits_sensor
    assert STAR.estimator_keywords(None, 1.0) == {} and STAR.lone_line[0] == "not-a-star"
    assert "direction_deg" in STAR.record_fields and STAR.load("figure").__name__ == "plot_star"
    with pytest.raises(ParameterError, match="a star target is no straight line"):
        imgmtf.Target("star")

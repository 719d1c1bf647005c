"""A scan's sections and fits on one pool: the rows each stage gives
alone, in their order, the scene's fit the first task."""

import pytest

import imgmtf as im
import imgmtf.parallel
import imgmtf.scene.targetfit
from imgmtf.errors import ParameterError
from imgmtf.scene.afterscan import sections_and_fits
from imgmtf.scene.combine import summarise_scan
from imgmtf.scene.measure import scan_scene
from imgmtf.scene.sections import section_rows
from imgmtf.scene.targetfit import fit_targets
from imgmtf.sensor.scenes import QuadrantTarget, render_quadrants
from imgmtf.sensor.stages import Detector, GaussianOptics


@pytest.fixture(scope="module")
def two_targets(tmp_path_factory):
    """A tilted four-square target scanned, and its half-edges again as a
    second target: a scene of two targets (and so a scene's fit)."""
    sensor = im.Sensor(1.0, [GaussianOptics(0.32, 0.42), Detector(1.0, 1.0)])
    target = QuadrantTarget((60.4, 60.3), 16.8, (9000.0, 2500.0, 9000.0, 4500.0), 48.0)
    path = tmp_path_factory.mktemp("afterscan") / "target.tif"
    im.write_geotiff(path, render_quadrants(sensor, (121, 121), target, fill=True, noise_std_dn=25.0, seed=3).image)
    records = scan_scene(str(path))
    twin = [r.with_(site={"target_id": 2}) for r in records if r.site.get("target_id") == 1]
    records = [*records, *twin]
    return records, summarise_scan(records)


def rows(records):
    return [(r.status, r.site, r.figures) for r in records]


def test_the_rows_are_each_stages_own_in_order_with_the_sections_first(two_targets, monkeypatch):
    records, summaries = two_targets
    sections, fits = section_rows(summaries), fit_targets(records)
    assert [r.site.get("target_id") for r in fits[::2]] == [1, 2, None]
    assert rows(sections_and_fits(records, summaries, "auto")[0]) == rows(sections)
    kinds = []

    def in_turn(function, items, workers, **options):     # the pool's tasks, taken one by one and run here
        assert not isinstance(items, list)                 # (taken lazily)
        for kind, item in items:
            kinds.append((workers, kind, item[1].get("target_id") if kind == "fit" else
                          [each[1]["target_id"] for each in item] if kind == "fits" else None))
            yield function((kind, item))
    monkeypatch.setattr(imgmtf.parallel, "run_tasks", in_turn)
    made = imgmtf.scene.targetfit.fit_tasks
    monkeypatch.setattr(imgmtf.scene.targetfit, "fit_tasks",
                        lambda *a, **k: kinds.append("fit tasks made") or made(*a, **k))
    # on workers: the sections first, each target's (and the scene's) a task of its own: the pool takes
    # them all at once; the fits' tasks made only then; the measurements travel without their MTF
    # function, the fits the same; the targets' fits are sent the last-ranked (the noisiest, the
    # longest to fit) first; a few only, one to a task
    there = sections_and_fits(records, summaries, "auto", workers=2)
    assert kinds == [(2, "sections", None)] * 3 + ["fit tasks made", (2, "fit", None), (2, "fits", [2]),
                                                   (2, "fits", [1])]
    assert (rows(there[0]), rows(there[1])) == (rows(sections), rows(fits))
    assert sections_and_fits(records, summaries, None, workers=2)[1] == []
    # many, a few to a task (fits_per_task's own examples: 4 of 484 on 2 workers, 1 of 20)
    monkeypatch.setattr(imgmtf.scene.afterscan, "fits_per_task", lambda targets, workers: 2)
    kinds.clear()
    assert rows(sections_and_fits(records, summaries, "auto", workers=2)[1]) == rows(fits)
    assert kinds[5:] == [(2, "fits", [2, 1])]
    with pytest.raises(ParameterError, match="workers"):
        sections_and_fits(records, summaries, "auto", workers=0)


def test_on_workers_the_fits_name_their_half_edges_in_one_shared_block_freed_even_when_interrupted(
        two_targets, monkeypatch):
    from multiprocessing import shared_memory

    from imgmtf.scene.afterscan import Shared
    records, summaries = two_targets
    names = []

    def interrupted(function, items, workers, **options):
        items = list(items)
        fits = [item for kind, item in items if kind == "fit"] + \
            [each for kind, item in items if kind == "fits" for each in item]
        names.extend({item[0].name for item in fits if isinstance(item[0], Shared)})
        assert [len(item[3]) for item in fits] == [8, 4, 4]     # the scene's eight half-edges, each target's four
        raise KeyboardInterrupt
    monkeypatch.setattr(imgmtf.parallel, "run_tasks", interrupted)
    with pytest.raises(KeyboardInterrupt):
        sections_and_fits(records, summaries, "auto", workers=2)
    assert len(names) == 1
    with pytest.raises(FileNotFoundError):
        shared_memory.SharedMemory(name=names[0])

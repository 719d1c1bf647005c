"""Scan detection: the tiles read and searched by LSD, here or on workers."""
import numpy as np


def test_detection_on_workers_finds_the_segments_one_process_finds(tmp_path):
    """Tiles searched on two workers (the first of them here while the
    workers start) give the same segments, in the same order, as in this
    process: the tiles' pieces are joined in tile order."""
    import imgmtf as im
    from imgmtf.io import raster_info
    from imgmtf.parallel import prestart_workers
    from imgmtf.preloads import SCAN_TASK_MODULES
    from imgmtf.scene.detect import detect_segments, tile_windows
    from imgmtf.scene.settings import ScanSettings
    from imgmtf.sensor.scenes import QuadrantTarget, render_quadrants, texture
    scene = render_quadrants(im.Sensor(), (600, 700), QuadrantTarget((300.4, 290.3), 8.0, half_size_px=200.0),
                             field_dn=3000 + texture((600, 700), 300, seed=2), noise_std_dn=10.0, seed=3)
    path = tmp_path / "scene.tif"
    im.write_geotiff(path, scene.image)
    settings = ScanSettings(tile_px=256)
    assert len(tile_windows(raster_info(str(path)), settings.tile_px)) == 9
    here = detect_segments(str(path), settings)
    prestart_workers(2, SCAN_TASK_MODULES)      # as a scan does: its workers then start beside the first tiles
    there = detect_segments(str(path), settings, workers=2)
    assert len(here[0]) > 4
    np.testing.assert_array_equal(here[0], there[0])
    np.testing.assert_array_equal(here[1], there[1])


def test_to_8bit_maps_lo_hi_onto_0_255_rounded_and_clipped_leaving_the_tile_as_it_was():
    from imgmtf.scene.detect import to_8bit
    rng = np.random.default_rng(8)
    tile = rng.uniform(-500, 5000, (40, 50))
    tile[3, 4] = np.nan
    kept = tile.copy()
    out = to_8bit(tile, 100.0, 4000.0)
    filled = np.where(np.isfinite(tile), tile, np.median(tile[np.isfinite(tile)]))
    assert out.dtype == np.uint8 and np.array_equal(out, np.clip(np.rint((filled - 100.0) / 3900.0 * 255), 0, 255))
    assert np.array_equal(tile, kept, equal_nan=True)
    assert out.min() == 0 and out.max() == 255
    assert to_8bit(np.array([[100.0, 4000.0, 2050.0]]), 100.0, 4000.0).tolist() == [[0, 255, 128]]

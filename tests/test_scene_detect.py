"""Scan detection: the tiles read and searched by LSD, here or on workers."""
import numpy as np


def test_detection_on_workers_finds_the_segments_one_process_finds(tmp_path):
    """Tiles searched on two workers give the same segments, in the same
    order, as in this process: the tiles' pieces are joined in tile order."""
    import imgmtf as im
    from imgmtf.io import raster_info
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
    there = detect_segments(str(path), settings, workers=2)
    assert len(here[0]) > 4
    np.testing.assert_array_equal(here[0], there[0])
    np.testing.assert_array_equal(here[1], there[1])

"""imgmtf: measure the MTF of imaging sensors from edge and pulse targets.

The generic pushbroom sensor of Choi and Helder renders exact synthetic
chips (:class:`Sensor`, :class:`Target`, :func:`render`); the estimators
measure the MTF of any chip (:func:`measure_edge`, :func:`measure_pulse`).

Names are imported on first use, so ``import imgmtf`` stays cheap and a
command pays only for the libraries it needs.
"""
from __future__ import annotations

import importlib

from .errors import (
    ConfigError,
    FileWriteError,
    ImageContentError,
    ImageReadError,
    ImgmtfError,
    MultipleTargetsError,
    ParameterError,
    TargetNotFoundError,
    UnsuitableTargetError,
)

# public name -> the module that defines it
_LAZY = {
    "Sensor": "sensor.model", "SampledPSF": "sensor.model", "Target": "sensor.targets",
    "GroundNoise": "sensor.noise", "Chip": "sensor.rendering", "Renderer": "sensor.rendering",
    "render": "sensor.rendering",
    "measure_edge": "estimate.edge", "EdgeEstimator": "estimate.edge", "EdgeResult": "estimate.edge",
    "measure_pulse": "estimate.pulse", "PulseEstimator": "estimate.pulse", "PulseResult": "estimate.pulse",
    "measure_double_bar": "estimate.double_bar", "DoubleBarEstimator": "estimate.double_bar",
    "DoubleBarResult": "estimate.double_bar",
    "measure_points": "estimate.mtf2d.points", "PointsResult": "estimate.mtf2d.points",
    "PointsEstimator": "estimate.mtf2d.estimator", "PointArray": "sensor.points", "render_points": "sensor.points",
    "measure_star": "estimate.star.measure", "StarResult": "estimate.star.result",
    "StarEstimator": "estimate.star.estimator", "SiemensStar": "sensor.star", "render_star": "sensor.star",
    "METHODS": "estimate.resampling", "resample_profile": "estimate.resampling",
    "Bootstrap": "estimate.intervals", "Interval": "estimate.intervals", "Intervals": "estimate.intervals",
    "fit_sensor": "sensor_fit", "fit_bar_files": "bar_fit",
    "SensorFit": "estimate.fit", "FitRecord": "estimate.fit.record",
    "read_fit_record": "estimate.fit.record",
    "Raster": "io", "read_raster": "io", "write_geotiff": "io", "write_png": "io", "luminance": "inputs",
    "Record": "records", "measure_file": "batch", "MeasureSettings": "measure_settings",
    "VectorROIs": "vectors",
    "scan_scene": "scene.measure", "ScanSettings": "scene.settings", "summarise_scan": "scene.combine",
    "fit_targets": "scene.targetfit", "scan_scenes": "scene.series",
    "mtf2d_from_sections": "estimate.mtf2d", "MTF2D": "estimate.mtf2d",
    "run_selftest": "selftest",
    "QualityError": "estimate.gate", "TwoTargetsError": "estimate.gate",
    "Acquisition": "campaign.acquisitions", "read_acquisition": "campaign.acquisitions",
    "write_acquisition": "campaign.store", "read_layer": "campaign.store", "StoreError": "campaign.store",
    "design_filter": "restore.design", "RestorationFilter": "restore.design",
    "restore_file": "restore.apply", "RestoredFile": "restore.apply",
    "restore_image": "restore.restoration", "Restoration": "restore.restoration",
    "restoration_report": "restore.report", "RestorationReport": "restore.report",
}

__all__ = [
    "__version__", *_LAZY,
    "ImgmtfError", "ParameterError", "ConfigError", "FileWriteError", "ImageReadError",
    "ImageContentError", "TargetNotFoundError", "MultipleTargetsError", "UnsuitableTargetError",
]


def __getattr__(name: str):
    if name == "__version__":         # reading the package metadata costs a tenth of a second
        from .version import __version__
        return __version__
    if name not in _LAZY:
        raise AttributeError(f"module 'imgmtf' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)          # the public API, not this file's machinery (importlib, annotations)

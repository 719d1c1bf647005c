"""imgmtf: measure the MTF of imaging sensors from edge and pulse targets.

The generic pushbroom sensor of Choi and Helder renders exact synthetic
chips (:class:`Sensor`, :class:`Target`, :func:`render`); the estimators
measure the MTF of any chip (:func:`measure_edge`, :func:`measure_pulse`).
"""
__version__ = "0.1.0"

from .edge import EdgeEstimator, EdgeResult, measure_edge  # noqa: E402
from .errors import (ConfigError, FileWriteError, ImageContentError, ImageReadError,  # noqa: E402
                     ImgmtfError, MultipleTargetsError, ParameterError, TargetNotFoundError,
                     UnsuitableTargetError)
from .io import Raster, read_raster, write_geotiff  # noqa: E402
from .noise import GroundNoise  # noqa: E402
from .pulse import PulseEstimator, PulseResult, measure_pulse  # noqa: E402
from .rendering import Chip, Renderer, render  # noqa: E402
from .resampling import METHODS, resample_profile  # noqa: E402
from .selftest import run_selftest  # noqa: E402
from .sensor import SampledPSF, Sensor  # noqa: E402
from .targets import Target  # noqa: E402
from .uncertainty import Bootstrap, Interval  # noqa: E402

__all__ = [
    "__version__",
    "Sensor", "SampledPSF", "Target", "GroundNoise", "Chip", "Renderer", "render",
    "measure_edge", "EdgeEstimator", "EdgeResult", "measure_pulse", "PulseEstimator", "PulseResult",
    "METHODS", "resample_profile", "Bootstrap", "Interval",
    "Raster", "read_raster", "write_geotiff", "run_selftest",
    "ImgmtfError", "ParameterError", "ConfigError", "FileWriteError", "ImageReadError",
    "ImageContentError", "TargetNotFoundError", "MultipleTargetsError", "UnsuitableTargetError",
]

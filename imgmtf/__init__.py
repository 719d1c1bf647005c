"""imgmtf: measure the MTF of imaging sensors from edge and pulse targets.

The generic pushbroom sensor of Choi and Helder renders exact synthetic
chips (:class:`Sensor`, :class:`Target`, :func:`render`); the estimators
measure the MTF of any chip.
"""
__version__ = "0.1.0"

from .errors import (ConfigError, FileWriteError, ImageContentError, ImageReadError, ImgmtfError,  # noqa: E402
                     MultipleTargetsError, ParameterError, TargetNotFoundError,
                     UnsuitableTargetError)
from .noise import GroundNoise  # noqa: E402
from .rendering import Chip, Renderer, render  # noqa: E402
from .sensor import SampledPSF, Sensor  # noqa: E402
from .targets import Target  # noqa: E402

__all__ = [
    "__version__", "Sensor", "SampledPSF", "Target", "GroundNoise", "Chip", "Renderer", "render",
    "ImgmtfError", "ParameterError", "ConfigError", "FileWriteError", "ImageReadError", "ImageContentError",
    "TargetNotFoundError", "MultipleTargetsError", "UnsuitableTargetError",
]

"""Exception classes.

Every error imgmtf raises on purpose derives from :class:`ImgmtfError`, so a
caller (and the CLI) can tell a problem with the input from a bug.  Messages
are one line and name the offending value or file.  Each also derives from
the builtin a caller would catch without knowing imgmtf: a bad parameter is a
ValueError, a file that cannot be read or written an OSError (as rasterio's
and open()'s are).  Every public exception is importable from ``imgmtf``
(the quality gate's :class:`~imgmtf.estimate.gate.QualityError` too).
"""


class ImgmtfError(Exception):
    """Base class of all deliberate imgmtf errors.  ``reason`` is a short
    machine-readable code (what the scan reports for a rejected target)."""

    reason = "error"

    def __init__(self, message: str = "", *, reason: str | None = None):
        super().__init__(message)
        if reason is not None:
            self.reason = reason


class ParameterError(ImgmtfError, ValueError):
    """A parameter is out of its valid range or of the wrong kind."""

    reason = "parameter"


class ConfigError(ImgmtfError):
    """A configuration file (sensor TOML) cannot be read or is malformed."""

    reason = "config"


class FileWriteError(ImgmtfError, OSError):
    """An output file cannot be written (an OSError, as open()'s is)."""

    reason = "write"


class ImageReadError(ImgmtfError, OSError):
    """An image file cannot be opened or decoded, an OSError as rasterio's
    read errors are (``reason`` ``unreadable``;
    ``too-large`` for an image above the read limit, ``unsupported-type``
    for complex pixels)."""

    reason = "unreadable"


class ImageContentError(ImgmtfError):
    """An image was read but cannot be measured (NaN, flat, too small...)."""

    reason = "image"


class TargetNotFoundError(ImageContentError):
    """No usable edge or bar was found in the image."""

    reason = "no-target"


class MultipleTargetsError(ImageContentError):
    """More than one edge or bar was found where one was expected."""

    reason = "two-targets"


class UnsuitableTargetError(ImageContentError):
    """A target was found but cannot give a trustworthy MTF (angle, saturation...)."""

    reason = "unsuitable"

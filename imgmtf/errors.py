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
    machine-readable code (what the scan reports for a rejected target).

    Parameters
    ----------
    message : str, optional
        One line naming the offending value or file.
    reason : str, optional
        A short machine-readable code (default ``"error"``).

    Examples
    --------
    >>> import numpy as np
    >>> import imgmtf
    >>> try:
    ...     imgmtf.measure_edge(np.full((50, 50), 100.0))
    ... except imgmtf.ImgmtfError as error:
    ...     print(error.reason, "|", error)
    image | the image is flat: no contrast to measure
    """

    reason = "error"

    def __init__(self, message: str = "", *, reason: str | None = None):
        super().__init__(message)
        if reason is not None:
            self.reason = reason


class ParameterError(ImgmtfError, ValueError):
    """A parameter is out of its valid range or of the wrong kind.

    Parameters
    ----------
    message : str, optional
        One line naming the offending value or file.
    reason : str, optional
        A short machine-readable code (default ``"parameter"``).

    Examples
    --------
    >>> import imgmtf
    >>> imgmtf.Sensor(gsd_m=-1)
    Traceback (most recent call last):
    imgmtf.errors.ParameterError: sensor gsd_m must be finite and >= 0, got -1
    """

    reason = "parameter"


class ConfigError(ImgmtfError):
    """A configuration file (sensor TOML) cannot be read or is malformed.

    Parameters
    ----------
    message : str, optional
        One line naming the offending value or file.
    reason : str, optional
        A short machine-readable code (default ``"config"``).

    Examples
    --------
    >>> import imgmtf
    >>> imgmtf.Sensor.from_toml("missing.toml")
    Traceback (most recent call last):
    imgmtf.errors.ConfigError: missing.toml: cannot read sensor file: No such file or directory
    """

    reason = "config"


class FileWriteError(ImgmtfError, OSError):
    """An output file cannot be written (an OSError, as open()'s is).

    Parameters
    ----------
    message : str, optional
        One line naming the offending value or file.
    reason : str, optional
        A short machine-readable code (default ``"write"``).

    Examples
    --------
    >>> import numpy as np
    >>> import imgmtf
    >>> imgmtf.write_geotiff("no/such/folder/edge.tif", np.zeros((4, 4), np.uint16))
    Traceback (most recent call last):
    imgmtf.errors.FileWriteError: no/such/folder/edge.tif: cannot write: No such file or directory
    """

    reason = "write"


class ImageReadError(ImgmtfError, OSError):
    """An image file cannot be opened or decoded, an OSError as rasterio's
    read errors are (``reason`` ``unreadable``;
    ``too-large`` for an image above the read limit, ``unsupported-type``
    for complex pixels).

    Parameters
    ----------
    message : str, optional
        One line naming the offending value or file.
    reason : str, optional
        A short machine-readable code (default ``"unreadable"``).

    Examples
    --------
    >>> import imgmtf
    >>> imgmtf.read_raster("missing.tif")
    Traceback (most recent call last):
    imgmtf.errors.ImageReadError: missing.tif: no such file
    """

    reason = "unreadable"


#: the reasons of :class:`ImageReadError`: the file itself cannot be read (an input's
#: error, said on stderr as each command says it), not a measurement refused
READ_REASONS = frozenset({"unreadable", "too-large", "unsupported-type"})


class ImageContentError(ImgmtfError):
    """An image was read but cannot be measured (NaN, flat, too small...).

    Parameters
    ----------
    message : str, optional
        One line naming the offending value or file.
    reason : str, optional
        A short machine-readable code (default ``"image"``).

    Examples
    --------
    >>> import numpy as np
    >>> import imgmtf
    >>> imgmtf.measure_edge(np.full((50, 50), np.nan))
    Traceback (most recent call last):
    imgmtf.errors.ImageContentError: every pixel is NaN or nodata: nothing to measure
    """

    reason = "image"


class TargetNotFoundError(ImageContentError):
    """No usable edge or bar was found in the image.

    Parameters
    ----------
    message : str, optional
        One line naming the offending value or file.
    reason : str, optional
        A short machine-readable code (default ``"no-target"``).

    Examples
    --------
    >>> import numpy as np
    >>> import imgmtf
    >>> noise = 100.0 + np.random.default_rng(0).normal(0.0, 1.0, (50, 50))
    >>> imgmtf.measure_pulse(noise)
    Traceback (most recent call last):
    imgmtf.errors.TargetNotFoundError: no bar found: no straight line stands out of the noise
    """

    reason = "no-target"


class MultipleTargetsError(ImageContentError):
    """More than one edge or bar was found where one was expected.

    Parameters
    ----------
    message : str, optional
        One line naming the offending value or file.
    reason : str, optional
        A short machine-readable code (default ``"two-targets"``).

    Examples
    --------
    >>> import numpy as np
    >>> import imgmtf
    >>> band = np.full((60, 60), 200.0)
    >>> band[:, 20:40] = 1200.0                      # a wide bar: two edges
    >>> try:
    ...     imgmtf.measure_edge(band)
    ... except imgmtf.MultipleTargetsError as error:
    ...     print(error.reason)
    two-targets
    """

    reason = "two-targets"


class UnsuitableTargetError(ImageContentError):
    """A target was found but cannot give a trustworthy MTF (angle, saturation...).

    Parameters
    ----------
    message : str, optional
        One line naming the offending value or file.
    reason : str, optional
        A short machine-readable code (default ``"unsuitable"``).

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 45.0), 60)
    >>> try:
    ...     imgmtf.measure_edge(chip.image)
    ... except imgmtf.UnsuitableTargetError as error:
    ...     print(error.reason)
    angle
    """

    reason = "unsuitable"

"""Noise models: white system noise added to the output image, and the
paper's multi-scale ground noise added to the scene before the PSF."""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import ParameterError


@dataclass(frozen=True)
class GroundNoise:
    """The paper's multi-scale ground noise, added to the scene before the
    PSF: ``layers`` white-Gaussian images made of 1x1, 2x2, ..., layers x
    layers sub-pixel squares, each with a random grid offset; their sum has
    variance layers x layer_variance_dn2 (the paper: 20 x 100 = 2000 DN^2).

    Parameters
    ----------
    layers : int
        Number of layers, >= 1 (default 20).
    layer_variance_dn2 : float
        Variance of each layer, DN^2, >= 0 (default 100).

    Raises
    ------
    ParameterError
        ``layers`` not a positive integer, or a negative or non-finite
        variance.

    Examples
    --------
    >>> import numpy as np
    >>> from imgmtf import GroundNoise
    >>> field = GroundNoise().sample((400, 400), np.random.default_rng(0))   # sub-pixel cells
    >>> 1500 < float(field.var()) < 2500                                    # about 2000 DN^2
    True
    """

    layers: int = 20
    layer_variance_dn2: float = 100.0

    def __post_init__(self):
        if not isinstance(self.layers, int) or self.layers < 1:
            raise ParameterError(f"ground-noise layers must be a positive integer, got {self.layers!r}")
        if not math.isfinite(self.layer_variance_dn2) or self.layer_variance_dn2 < 0:
            raise ParameterError(f"ground-noise layer variance must be >= 0 DN^2, got {self.layer_variance_dn2}")

    def to_dict(self) -> dict:
        return asdict(self)

    def sample(self, shape: tuple[int, int], rng: np.random.Generator) -> np.ndarray:
        """The composite noise field on a sub-pixel grid of ``shape`` (DN).

        Parameters
        ----------
        shape : (int, int)
            The grid's (rows, cols), sub-pixel cells.
        rng : numpy.random.Generator
            The source of the noise.

        Returns
        -------
        numpy.ndarray
            The sum of the layers, DN.
        """
        return sum((self.layer(k, shape, rng) for k in range(1, self.layers + 1)),
                   np.zeros(shape))

    def layer(self, grain: int, shape: tuple[int, int], rng: np.random.Generator) -> np.ndarray:
        """One layer: white Gaussian noise constant over ``grain`` x ``grain``
        cells, its grid shifted by a random offset in each axis.

        Parameters
        ----------
        grain : int
            The side of the layer's constant blocks, sub-pixel cells.
        shape : (int, int)
            The grid's (rows, cols), sub-pixel cells.
        rng : numpy.random.Generator
            The source of the noise.

        Returns
        -------
        numpy.ndarray
            The layer, DN.
        """
        rows, cols = shape
        coarse = rng.normal(0.0, math.sqrt(self.layer_variance_dn2),
                            (rows // grain + 2, cols // grain + 2))
        oy, ox = rng.integers(0, grain, size=2)
        fine = np.repeat(np.repeat(coarse, grain, axis=0), grain, axis=1)
        return fine[oy: oy + rows, ox: ox + cols]


def add_system_noise(image: np.ndarray, std_dn: float, rng: np.random.Generator) -> np.ndarray:
    """``image`` plus white Gaussian noise of standard deviation ``std_dn``."""
    if not math.isfinite(std_dn) or std_dn < 0:
        raise ParameterError(f"noise standard deviation must be >= 0 DN, got {std_dn}")
    if std_dn == 0:
        return image
    return image + rng.normal(0.0, std_dn, image.shape)

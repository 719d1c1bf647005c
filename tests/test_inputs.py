import numpy as np
import pytest

from imgmtf.errors import ParameterError
from imgmtf.inputs import check_number


@pytest.mark.parametrize("value, expected", [(2, 2.0), (np.float32(2.5), 2.5), (np.array(3.0), 3.0),
                                             (np.array(4, dtype=np.int64), 4.0)])
def test_numbers_numpy_scalars_and_0d_arrays_are_floats(value, expected):
    number = check_number("x", value)
    assert number == expected and type(number) is float


@pytest.mark.parametrize("value, kwargs, message", [
    (10**400, {}, "x must be finite, got an integer of 401 digits"),
    (np.array([1.0]), {}, "x must be a number"),
    (5.0, dict(high=3.0), "x must be at most 3, got 5.0"),
    (1.0, dict(low=2.0), "x must be at least 2, got 1.0"),
    (5.0, dict(low=0.0, high=3.0), r"x must lie in \[0, 3\], got 5.0"),
])
def test_bad_numbers_are_parameter_errors_naming_the_value(value, kwargs, message):
    with pytest.raises(ParameterError, match=message):
        check_number("x", value, **kwargs)


def test_floats_in_tiny_units_are_not_counts_and_measure_as_in_dn():
    """A float image in small physical units is measured as the same image
    in DN (the estimate is scale-free); values all within 1e-6 of 0 are not
    whole numbers of DN, and an image spanning less than 1e-6 is refused."""
    import imgmtf as im
    from imgmtf.errors import ImageContentError
    from imgmtf.inputs import quantum
    chip = im.Renderer(im.Sensor(), 60)(im.Target("edge", 6.0, 200.0, 1200.0), noise_std_dn=5.0, seed=1).image
    chip = chip.astype(float)
    assert quantum(chip, chip.dtype) == 1.0 and quantum(chip * 1e-9, chip.dtype) == 0.0
    reference = im.measure_edge(chip)
    for scale in (1e-3, 1e-8):
        scaled = im.measure_edge(chip * scale)
        assert scaled.mtf_nyquist == pytest.approx(reference.mtf_nyquist, abs=1e-9)
        assert scaled.snr == pytest.approx(reference.snr, rel=1e-6)
    with pytest.raises(ImageContentError, match="span only"):
        im.measure_edge(chip * 1e-13)

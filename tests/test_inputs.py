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

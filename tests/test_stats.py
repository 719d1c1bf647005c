import math

import pytest

from imgmtf._stats import t_quantile
from imgmtf.errors import ParameterError


@pytest.mark.parametrize("dof", [1, 2, 3, 4, 7, 30, 99, 1000, 1001, 20000, 10 ** 6])
def test_t_quantile_is_students(dof):
    # the series up to 1000 degrees of freedom, the expansion in 1 / dof beyond
    from scipy.special import stdtrit
    for p in (1e-4, 0.001, 0.05, 0.5, 0.6, 0.9, 0.975, 0.995, 0.9995, 1 - 1e-4):
        assert t_quantile(p, dof) == pytest.approx(float(stdtrit(dof, p)), rel=1e-10, abs=1e-12)


def test_t_quantile_closed_forms_and_bad_arguments():
    # dof 1 is Cauchy's, dof 2 has t = (2p - 1) sqrt(2 / (4 p (1 - p)))
    assert t_quantile(0.9, 1) == pytest.approx(math.tan(math.pi * 0.4), rel=1e-12)
    assert t_quantile(0.9, 2) == pytest.approx(0.8 * math.sqrt(2 / (4 * 0.9 * 0.1)), rel=1e-12)
    for p, dof in ((0.0, 5), (1.0, 5), (0.9, 0), (0.9, 2.5)):
        with pytest.raises(ParameterError):
            t_quantile(p, dof)

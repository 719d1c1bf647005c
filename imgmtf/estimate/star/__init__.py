"""The MTF in every direction from a Siemens star (ISO 12233:2017's
sinusoidal s-SFR star, or a binary one), beside the 1-D pipeline of edges
and bars: :mod:`.centre` (where it is, its cycles and profile),
:mod:`.rings` (each ring of each direction fitted with the known sinusoid),
:mod:`.contrast` (the full-contrast divisor), :mod:`.curve` (the MTF
against frequency), :mod:`.measure` (:func:`measure_star`), :mod:`.result`
and :mod:`.estimator`."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .estimator import StarEstimator
    from .measure import measure_star
    from .result import StarDirection, StarResult

#: loaded when first asked for: they need SciPy
_NAMES = {"StarEstimator": ".estimator", "measure_star": ".measure", "StarDirection": ".result",
          "StarResult": ".result"}


def __getattr__(name: str) -> Any:
    if name in _NAMES:
        from importlib import import_module
        return getattr(import_module(_NAMES[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["StarDirection", "StarEstimator", "StarResult", "measure_star"]

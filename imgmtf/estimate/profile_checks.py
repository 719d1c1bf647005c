"""The gate's checks on a measured profile, one module each, registered
here: each takes the chip's :class:`.evidence.Evidence` and returns its
checks and warnings.  A new check is one module and one line below."""
from __future__ import annotations

from collections.abc import Callable

from .blocks import block_boundaries
from .blur_along import uniform_blur
from .evidence import Evidence
from .gate import Check
from .settling import settled_sides

ProfileCheck = Callable[[Evidence], tuple[list[Check], list[str]]]

#: run in this order on every measured edge and bar
PROFILE_CHECKS: tuple[ProfileCheck, ...] = (block_boundaries, settled_sides, uniform_blur)


def run_profile_checks(evidence: Evidence, made: dict[ProfileCheck, tuple[list[Check], list[str]]] | None = None
                       ) -> tuple[list[Check], list[str]]:
    """Every registered check's outcome on ``evidence``: (checks, warnings).
    ``made``: the outcomes of checks already made on it (among other
    chips', :mod:`.asks`), by check."""
    checks: list[Check] = []
    warnings: list[str] = []
    for check in PROFILE_CHECKS:
        more_checks, more_warnings = made[check] if made and check in made else check(evidence)
        checks += more_checks
        warnings += more_warnings
    return checks, warnings

"""Whether this import runs in the workers' fork server as it preloads its modules: for the
modules meant for the server alone (:mod:`imgmtf._server_exit`, :mod:`imgmtf._server_numpy`)."""
from __future__ import annotations

import sys
from types import FrameType


def in_fork_server() -> bool:
    """Whether this import runs inside the fork server's preloading."""
    server = sys.modules.get("multiprocessing.forkserver")
    if server is None:
        return False
    frame: FrameType | None = sys._getframe()
    while frame is not None:
        if frame.f_code is server.main.__code__:
            return True
        frame = frame.f_back
    return False

"""The campaign report's figures: each embedded in the page (which opens
offline, as it was written) and opening at full resolution from it (a
PNG file beside the page, or the store's own figure file), and the
store's figures that are no longer where it says (reported, not
silently dropped)."""
from __future__ import annotations

import base64
import io
import os
from dataclasses import dataclass, field
from pathlib import Path

from PIL import Image

from ..errors import FileWriteError
from .store import figure_path

EMBED_DPI = 90                  # the page's copy of a report figure
FILE_DPI = 150                  # the file it opens at full resolution
_KINDS = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".svg": "image/svg+xml"}


@dataclass
class Figures:
    """Where a report's figures go and what was missing.

    ``out_dir`` is the report's folder (its own figures go to
    ``out_dir/figures``); ``store`` the campaign store whose figure paths
    are resolved; ``missing`` collects (stored path, where it was looked
    for) of every figure the store names that is not there.
    """

    out_dir: Path
    store: Path
    missing: list[tuple[str, str]] = field(default_factory=list)
    _count: int = 0

    def clear(self) -> None:
        """Remove the figures an earlier report wrote into ``figures/``
        (a campaign with fewer series leaves none of them behind)."""
        for old in (self.out_dir / "figures").glob("[0-9][0-9]-*.png"):
            try:
                old.unlink()
            except OSError:
                pass            # held open elsewhere: overwritten or left, never fatal

    def render(self, fig, name: str) -> tuple[str, str]:
        """A matplotlib figure written to ``figures/<name>.png`` at
        :data:`FILE_DPI`: its embedded ``src`` (at :data:`EMBED_DPI`) and
        the file's link relative to the page.

        Raises
        ------
        FileWriteError
            The figure's file cannot be written.
        """
        folder = self.out_dir / "figures"
        self._count += 1
        path = folder / f"{self._count:02d}-{name}.png"
        try:
            folder.mkdir(exist_ok=True)
            fig.savefig(path, format="png", dpi=FILE_DPI)
        except OSError as exc:
            raise FileWriteError(f"{path}: cannot write: {exc.strerror or exc}") from None
        # the page's copy is the file scaled down, not the figure drawn a
        # second time: drawing (layout, ticks) is most of a report's time
        with Image.open(path) as full:
            width, height = (round(n * EMBED_DPI / FILE_DPI) for n in full.size)
            buffer = io.BytesIO()
            # opaque RGB (the figure's background is white) and zlib's default level: PIL's
            # optimize=True took a fifth of a report's time for 0.4 % fewer bytes
            full.convert("RGB").resize((width, height), Image.Resampling.LANCZOS).save(buffer, format="png")
        return "data:image/png;base64," + base64.b64encode(buffer.getvalue()).decode("ascii"), \
            path.relative_to(self.out_dir).as_posix()

    def stored(self, stored: str | None) -> tuple[str, str] | None:
        """A figure the store names (an overview, an edge figure): its
        embedded ``src`` and a link to the file, relative to the page
        (absolute when no relative path joins them); None, and noted in
        :attr:`missing`, when it is not where the store says."""
        path = figure_path(self.store, stored)
        if path is None:
            return None
        kind = _KINDS.get(path.suffix.lower())
        try:
            data = path.read_bytes() if kind else b""
        except OSError:
            data = b""
        if not data:
            self.missing.append((str(stored), str(path.absolute())))
            return None
        try:
            link = Path(os.path.relpath(path.resolve(), self.out_dir.resolve())).as_posix()
        except ValueError:
            link = path.resolve().as_uri()
        return f"data:{kind};base64," + base64.b64encode(data).decode("ascii"), link

"""What the command line adds to a refusal: the option that answers it, looked
up by the command that met it and the refusal's reason code.

The library's message says what is wrong with the data; this table says what
to do about it on the command line, so that no library message names a flag.
A command that measures one file (``measure``, ``fit``, ``restore``, ...)
and ``scan``, which finds the targets in a scene itself, answer some reasons
differently: a chip holding two targets wants ``--roi``, a scan's candidate
that reaches another target wants a smaller ``--margin``.
"""
from __future__ import annotations

from dataclasses import dataclass

#: the commands a hint is written for: one file measured as given, or a scene searched
CHIP, SCAN = "chip", "scan"


@dataclass(frozen=True)
class Hint:
    """The option that answers the refusals with code ``reason`` that
    ``command`` (:data:`CHIP` or :data:`SCAN`) meets, when the message
    holds ``words`` (a reason some refusals share with others no option
    moves)."""

    command: str
    reason: str
    text: str
    words: str = ""


HINTS = (
    Hint(CHIP, "two-targets", "--roi X,Y,W,H crops it to one target"),
    Hint(CHIP, "not-an-edge", "--target pulse measures a bar"),
    Hint(CHIP, "not-a-bar", "--target edge measures an edge"),
    Hint(CHIP, "points", "--target points measures point targets"),
    Hint(CHIP, "not-points", "--target edge or --target pulse measures it"),
    Hint(CHIP, "too-large", "--roi X,Y,W,H measures a window"),
    Hint(CHIP, "bands", "--band N chooses one, --band all measures each"),
    Hint(CHIP, "bar-width", "--pulse-width gives it"),
    Hint(CHIP, "fit", "--stages fits fewer, --hold holds some"),
    Hint(CHIP, "no-signal", "--signal-std gives it"),
    # a too-short line, not too few rows clear of the junctions, which no option moves
    Hint(SCAN, "too-short", "--min-length sets the minimum", words="shorter than the minimum"),
    Hint(SCAN, "two-targets", "--margin sets the ROI's reach"),
    Hint(SCAN, "not-an-edge", "--target pulse measures bars"),
    Hint(SCAN, "not-a-bar", "--target edge measures edges"),
)

# refusals of one file that a scan of it resolves: the scan finds each edge and
# bar and measures them one by one, away from fill and from each other
SCAN_SOLVES = frozenset({"fill", "two-targets"})


def option_hints(command: str, reason: str | None, message: str = "") -> list[str]:
    """The options in :data:`HINTS` that answer a refusal ``command`` met."""
    return [h.text for h in HINTS if h.command == command and h.reason == reason and h.words in message]


def refusal_hint(reason: str | None, message: str = "", path: str | None = None) -> str:
    """What the CLI adds to the refusal of one file, in parentheses: the
    option that answers its reason, ``imgmtf scan`` where the file holds
    fill, several targets or a checkerboard's corner, and the flag that
    overrules the gate; ``""`` when nothing answers it."""
    from ..estimate.gate import FORCIBLE
    hints = option_hints(CHIP, reason, message)
    if reason in SCAN_SOLVES or (reason == "not-straight" and "meet inside the chip" in message):
        hints.append(f"imgmtf scan {path or 'FILE'} finds and measures each edge in it")
    if reason in FORCIBLE:
        hints.append("--force measures it anyway")
    return f" ({'; '.join(hints)})" if hints else ""


def rejection_hint(reason: str | None, message: str) -> str:
    """What the CLI adds to a scan's rejected candidate, in parentheses;
    ``""`` when no option moves the limit it failed."""
    hints = option_hints(SCAN, reason, message)
    return f" ({'; '.join(hints)})" if hints else ""

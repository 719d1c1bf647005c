"""What the command line adds to a refusal: the option that answers it, looked
up by the command that met it and the refusal's reason code.

The library's message says what is wrong with the data; this table says what
to do about it on the command line, so that no library message names a flag.
A command that measures one file (``measure``, ``fit``, ``restore``, ...)
and ``scan``, which finds the targets in a scene itself, answer some reasons
differently: a chip holding two targets wants ``--roi``, a scan's candidate
that reaches another target wants a smaller ``--margin``.  A command is
given only the hints whose options it has (:func:`command_options`): ``fit``
is never told of ``--pulse-width``, ``restore`` of ``--force``.
"""
from __future__ import annotations

import re
from collections.abc import Collection
from dataclasses import dataclass

from ..kinds import kind_names

#: the commands a hint is written for: one file measured as given, or a scene searched; and
#: the warnings of a measurement (keyed by their words, having no reason code)
CHIP, SCAN, WARNING = "chip", "scan", "warning"


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
    #: the commands (by name) that take the values the text names, when not every one with its options does
    only: frozenset[str] = frozenset()


def other_targets(kind: str) -> str:
    """``--target`` with every registered kind but ``kind``, as a hint
    names them.

    Examples
    --------
    >>> other_targets("star")
    '--target edge, pulse, points or double-bar'
    """
    others = [name for name in kind_names() if name != kind]
    return f"--target {', '.join(others[:-1])} or {others[-1]}"


#: the hint to a double bar refused as one bar or an edge, the spacing its profile shows filled in
PAIR_HINT = "--target double-bar --pulse-width W --gap G measures them"
#: the spacing of two bars as the refusal's message gives it
PAIR_SPACING = re.compile(r"two parallel bars (\d+(?:\.\d+)?) px apart")


HINTS = (
    Hint(CHIP, "two-targets", "--roi X,Y,W,H crops it to one target"),
    Hint(CHIP, "not-an-edge", "--target pulse measures a bar"),
    Hint(CHIP, "not-a-bar", "--target edge measures an edge"),
    Hint(CHIP, "points", "--target points measures point targets"),
    Hint(CHIP, "not-points", f"{other_targets('points')} measures it"),
    Hint(CHIP, "not-a-star", f"{other_targets('star')} measures what it holds"),
    Hint(CHIP, "star", "--target star measures a Siemens star"),
    # an image too large, not a window too large (which a smaller --roi answers, as its message says)
    Hint(CHIP, "too-large", "--roi X,Y,W,H measures a window", words="measure a window of it"),
    Hint(CHIP, "no-crs", "--roi X,Y,W,H measures a window in pixels"),
    Hint(CHIP, "bands", "--band N chooses one"),
    Hint(CHIP, "bands", "--band all measures each", only=frozenset({"measure"})),
    Hint(CHIP, "bar-width", "--pulse-width gives it"),
    Hint(CHIP, "double-bar", PAIR_HINT),
    Hint(CHIP, "fit", "--stages fits fewer, --hold holds some"),
    # a scene's half-edges: fit takes the ROIs scan prints, one per file named
    Hint(CHIP, "fill", "--roi X,Y,W,H once per file fits the edges imgmtf scan finds", only=frozenset({"fit"})),
    Hint(CHIP, "no-signal", "--signal-std gives it"),
    Hint(CHIP, "misfit", "--allow-misfit restores with it anyway"),
    Hint(CHIP, "noise-dominated", "--max-noise-gain G sets the noise budget, the target then met only within it; "
                                  "a lower --target-nyquist asks less"),
    # a too-short line, not too few rows clear of the junctions, which no option moves
    Hint(SCAN, "too-short", "--min-length sets the minimum", words="shorter than the minimum"),
    Hint(SCAN, "two-targets", "--margin sets the ROI's reach"),
    Hint(SCAN, "not-an-edge", "--target pulse measures bars"),
    Hint(SCAN, "not-a-bar", "--target edge measures edges"),
    Hint(SCAN, "few-points", "--point-spacing PX groups targets farther apart, a star field's whole frame with "
                             "its size"),
    Hint(WARNING, "", "--track-azimuth DEG gives it", words="give the track's azimuth"),
    # a photo's gamma-encoded values, RGB or 8-bit
    Hint(WARNING, "", "--transfer srgb or --transfer gamma:G linearises them",
         words="the sRGB or a gamma transfer curve"),
)

# refusals of one file that a scan of it resolves: the scan finds each edge and
# bar and measures them one by one, away from fill and from each other
SCAN_SOLVES = frozenset({"fill", "two-targets"})


#: an option named in a hint's text
OPTION = re.compile(r"--[a-z][a-z0-9-]*")


@dataclass(frozen=True)
class Command:
    """What a hint needs to know of the command that met a refusal: its
    name and its options (every spelling: ``--roi``, ``--no-progress``)."""

    name: str
    options: frozenset[str]

    @classmethod
    def of(cls, command) -> Command:
        """The :class:`Command` of a click command."""
        options = {o for p in command.params for o in (*getattr(p, "opts", ()), *getattr(p, "secondary_opts", ()))}
        return cls(command.name or "", frozenset(options))

    def gives(self, text: str, only: Collection[str] = ()) -> bool:
        """True when every option ``text`` names is one of this command's."""
        return (not only or self.name in only) and all(o in self.options for o in OPTION.findall(text))


def command_options(command=None) -> Command | None:
    """The running click command (or ``command``) as a :class:`Command`;
    None outside a command (every hint is then given)."""
    if command is None:
        import click
        context = click.get_current_context(silent=True)
        if context is None:
            return None
        command = context.command
    return Command.of(command)


def option_hints(command: str, reason: str | None, message: str = "", *, running: Command | None = None) -> list[str]:
    """The options in :data:`HINTS` that answer a refusal ``command`` met
    (only those ``running`` has, when given)."""
    return [_filled(h.text, message) for h in HINTS if h.command == command and h.reason == reason
            and h.words in message and (running is None or running.gives(h.text, h.only))]


def _filled(text: str, message: str) -> str:
    """A hint with what the refusal measured: a double bar's spacing
    (its bars' centres apart, the width plus the gap)."""
    spacing = PAIR_SPACING.search(message)
    if text == PAIR_HINT and spacing:
        return f"{text}, W + G near {spacing.group(1)} px, the peaks' spacing"
    return text


def refusal_hint(reason: str | None, message: str = "", path: str | None = None, *,
                 running: Command | None = None) -> str:
    """What the CLI adds to the refusal of one file, in parentheses: the
    option that answers its reason, ``imgmtf scan`` where the file holds
    fill, several targets or a checkerboard's corner, and the flag that
    overrules the gate; ``""`` when nothing answers it.  Only the options
    the command ``running`` (default: the click command running) has."""
    from ..estimate.gate import FORCIBLE
    running = running or command_options()
    hints = option_hints(CHIP, reason, message, running=running)
    if reason in SCAN_SOLVES or (reason == "not-straight" and "meet inside the chip" in message):
        hints.append(f"imgmtf scan {path or 'FILE'} finds and measures each edge in it")
    if reason in FORCIBLE and (running is None or running.gives("--force")):
        hints.append("--force measures it anyway")
    return f" ({'; '.join(hints)})" if hints else ""


def rejection_hint(reason: str | None, message: str, *, running: Command | None = None) -> str:
    """What the CLI adds to a scan's rejected candidate, in parentheses;
    ``""`` when no option moves the limit it failed."""
    hints = option_hints(SCAN, reason, message, running=running or command_options())
    return f" ({'; '.join(hints)})" if hints else ""


def hinted_warning(message: str, *, running: Command | None = None) -> str:
    """A warning as the CLI prints it: with the option that answers it in
    parentheses, when the command running has one.

    Examples
    --------
    >>> hinted_warning("the direction is unknown; give the track's azimuth to label it")
    "the direction is unknown; give the track's azimuth to label it (--track-azimuth DEG gives it)"
    """
    hints = option_hints(WARNING, "", message, running=running or command_options())
    return message + (f" ({'; '.join(hints)})" if hints else "")

"""The installed package's version, read once from its metadata (the one
place it is defined is ``pyproject.toml``)."""
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("imgmtf")
except PackageNotFoundError:      # run from a source tree that was never installed
    __version__ = "0+unknown"

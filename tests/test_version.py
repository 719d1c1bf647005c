"""imgmtf.version: the one place the version is written, and what the
installed package's metadata says."""
import importlib.metadata
import re

from imgmtf.version import __version__


def test_the_installed_metadata_carries_the_version_written_in_the_package():
    assert __version__ == importlib.metadata.version("imgmtf")
    assert re.fullmatch(r"\d+\.\d+\.\d+", __version__)

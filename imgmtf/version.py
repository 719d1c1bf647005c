"""The package's version, written here and only here: ``pyproject.toml``
takes it from this file when the package is built
(``[tool.setuptools.dynamic]``, read statically), so the installed
metadata and a running program agree without looking the metadata up at
every start (``importlib.metadata`` costs 20-30 ms to import, a tenth of a
one-chip ``imgmtf measure``)."""

__version__ = "0.1.0"

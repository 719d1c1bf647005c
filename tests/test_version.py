"""imgmtf.version: the version read from the .dist-info that importlib.metadata reads.

The path cases run in a fresh interpreter: importing the importlib_metadata
backport (Dask does) installs a distribution finder of its own for the rest
of the process, and the fast path then rightly defers to importlib."""
import importlib.metadata
import subprocess
import sys

from imgmtf.version import __version__


def _dist(folder, name, version):
    info = folder / name
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.4\nName: fakedist\nVersion: {version}\n\nVersion: not me\n")


def _fresh(path, code):
    """``code``'s printed line in a new interpreter with ``path`` before sys.path."""
    script = (f"import sys, importlib.metadata; sys.path[:0] = {[str(p) for p in path]!r}; "
              f"from imgmtf.version import dist_info_version as fast; print({code})")
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout.strip()


def test_the_installed_version_is_importlib_metadatas():
    assert __version__ == importlib.metadata.version("imgmtf")


def test_the_first_folder_on_the_path_that_holds_the_distribution_wins_as_for_importlib(tmp_path):
    _dist(tmp_path / "a", "Fake_Dist-2.0.dist-info", "2.0")
    _dist(tmp_path / "b", "fakedist-1.0.dist-info", "1.0")
    path = [tmp_path / "empty", tmp_path / "a", tmp_path / "b"]
    assert _fresh(path, "fast('fake.dist'), importlib.metadata.version('fake.dist')") == "2.0 2.0"


def test_layouts_it_does_not_follow_are_left_to_importlib(tmp_path):
    _dist(tmp_path / "two", "fakedist-1.0.dist-info", "1.0")
    _dist(tmp_path / "two", "fakedist-3.0.dist-info", "3.0")    # two in one folder: importlib's listing order decides
    (tmp_path / "egg").mkdir()
    (tmp_path / "egg" / "fakedist.egg-info").write_text("Version: 4.0\n")
    assert _fresh([tmp_path / "two"], "fast('fakedist'), fast('no-such-distribution-here')") == "None None"
    assert _fresh([tmp_path / "egg"], "fast('fakedist')") == "None"

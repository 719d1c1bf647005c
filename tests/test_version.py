"""imgmtf.version: the version read from the .dist-info that importlib.metadata reads."""
import importlib.metadata
import sys

from imgmtf.version import __version__, dist_info_version


def _dist(folder, name, version):
    info = folder / name
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.4\nName: fakedist\nVersion: {version}\n\nVersion: not me\n")


def test_the_installed_version_is_importlib_metadatas():
    assert __version__ == importlib.metadata.version("imgmtf")


def test_the_first_folder_on_the_path_that_holds_the_distribution_wins_as_for_importlib(tmp_path, monkeypatch):
    _dist(tmp_path / "a", "Fake_Dist-2.0.dist-info", "2.0")
    _dist(tmp_path / "b", "fakedist-1.0.dist-info", "1.0")
    monkeypatch.setattr(sys, "path", [str(tmp_path / "empty"), str(tmp_path / "a"), str(tmp_path / "b"), *sys.path])
    assert dist_info_version("fake.dist") == importlib.metadata.version("fake.dist") == "2.0"


def test_layouts_it_does_not_follow_are_left_to_importlib(tmp_path, monkeypatch):
    _dist(tmp_path, "fakedist-1.0.dist-info", "1.0")
    _dist(tmp_path, "fakedist-3.0.dist-info", "3.0")      # two in one folder: importlib's listing order decides
    monkeypatch.setattr(sys, "path", [str(tmp_path), *sys.path])
    assert dist_info_version("fakedist") is None
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "fakedist.egg-info").write_text("Version: 4.0\n")
    monkeypatch.setattr(sys, "path", [str(tmp_path / "other"), *sys.path])
    assert dist_info_version("fakedist") is None
    assert dist_info_version("no-such-distribution-here") is None

import imgmtf


def test_dir_lists_the_public_api_and_every_name_resolves():
    assert dir(imgmtf) == sorted(imgmtf.__all__)
    assert "importlib" not in dir(imgmtf) and "annotations" not in dir(imgmtf)
    for name in imgmtf.__all__:
        assert getattr(imgmtf, name) is not None


def test_every_public_exception_is_importable_from_the_package():
    """Every exception class imgmtf raises on purpose is reachable as
    imgmtf.<Name> (the quality gate's too), and listed in __all__."""
    import importlib
    import pkgutil
    found = set()
    for info in pkgutil.walk_packages(imgmtf.__path__, "imgmtf."):
        if info.name.startswith("imgmtf.cli"):
            continue
        module = importlib.import_module(info.name)
        found |= {name for name, value in vars(module).items()
                  if isinstance(value, type) and issubclass(value, imgmtf.ImgmtfError)
                  and value.__module__ == info.name}
    found |= {"ImgmtfError"}
    assert {"QualityError", "TwoTargetsError", "ImageReadError"} <= found
    for name in found:
        assert name in imgmtf.__all__ and issubclass(getattr(imgmtf, name), imgmtf.ImgmtfError)
    assert imgmtf.QualityError.__name__ == "QualityError"

import imgmtf


def test_dir_lists_the_public_api_and_every_name_resolves():
    assert dir(imgmtf) == sorted(imgmtf.__all__)
    assert "importlib" not in dir(imgmtf) and "annotations" not in dir(imgmtf)
    for name in imgmtf.__all__:
        assert getattr(imgmtf, name) is not None

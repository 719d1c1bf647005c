import numpy as np

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


def _imports(path, package, modules):
    """The package's modules that the module at ``path`` imports anywhere in
    it (in functions and under TYPE_CHECKING too), by their dotted names."""
    import ast
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else []
            base = ".".join(base + ([node.module] if node.module else [])) if node.level else node.module or ""
            found |= {f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names}
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
    resolved = set()
    for name in found:
        while name and name not in modules:        # a name imported from a module: the module
            name = name.rpartition(".")[0]
        resolved.add(name)
    return resolved - {""}


def test_no_import_cycle_between_modules():
    # the data flows one way through the house: a module never imports one
    # that imports it, however indirectly (a package's own __init__ aside)
    import pathlib

    from scipy.sparse import csr_array
    from scipy.sparse.csgraph import connected_components
    root = pathlib.Path(imgmtf.__file__).parent
    paths = {}
    for path in root.rglob("*.py"):
        parts = ["imgmtf", *path.relative_to(root).with_suffix("").parts]
        paths[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    names = sorted(paths)
    index = {name: k for k, name in enumerate(names)}
    edges = [(index[name], index[target]) for name in names
             for target in _imports(paths[name], name.split(".") if paths[name].name == "__init__.py"
                                    else name.split(".")[:-1], paths)
             if target != name and not name.startswith(target + ".")]
    rows, cols = zip(*edges)
    graph = csr_array((np.ones(len(edges)), (rows, cols)), shape=(len(names), len(names)))
    count, labels = connected_components(graph, directed=True, connection="strong")
    cycles = [sorted(n for n, label in zip(names, labels) if label == c) for c in range(count)
              if np.count_nonzero(labels == c) > 1]
    assert len(names) > 80 and len(edges) > 200 and cycles == []


def test_no_module_over_600_lines():
    # a room with one job stays small enough to read: a module that grows past
    # this has taken on a second job and is split (docs/architecture.md)
    import pathlib
    root = pathlib.Path(imgmtf.__file__).parent
    long = {str(p.relative_to(root)): n for p in root.rglob("*.py") if (n := len(p.read_text().splitlines())) > 600}
    assert long == {}

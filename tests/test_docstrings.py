"""numpydoc's validator on the docstrings: the public API (``imgmtf.__all__``)
documents every parameter with its type, what it returns and an example, in
sections numpydoc knows and in its order; every other public function, class
and method of the package, where it has such sections, writes them so too.

Style (See Also, an extended summary, a one-line summary...) is left to
review.  numpydoc is in the ``lint`` extra: without it these tests skip.
"""
import dataclasses
import importlib
import inspect
import pkgutil
import warnings

import pytest

validate = pytest.importorskip("numpydoc.validate")
docscrape = pytest.importorskip("numpydoc.docscrape")

import imgmtf  # noqa: E402
import imgmtf.plot  # noqa: E402

#: the codes about sections and types (numpydoc's list: its docs, "Validation")
SECTIONS_AND_TYPES = {
    "GL02",   # closing quotes on a line of their own
    "GL06",   # an unknown section (``Example`` for ``Examples``)
    "GL07",   # sections out of order
    "PR01",   # a parameter not documented
    "PR02",   # a documented parameter the signature does not have
    "PR03",   # parameters in another order than the signature's
    "PR04",   # a parameter without a type
    "PR07",   # a parameter without a description
    "PR08",   # a description that does not start with a capital letter
    "PR10",   # "name: type" for "name : type"
    "RT01",   # no Returns section
    "RT03",   # a return value without a description
    "EX01",   # no Examples section
}
#: what any docstring with sections must get right; the rest (PR01, RT01,
#: EX01: a section to write) is asked of the public API only
WRITTEN_RIGHT = {"GL06", "GL07", "PR02", "PR03", "PR04", "PR07", "PR08", "PR10", "RT03"}

#: the functions and classes of the public API (not its constants: METHODS,
#: __version__), and the figures (imgmtf.plot)
API = sorted([name for name in imgmtf.__all__ if inspect.isfunction(getattr(imgmtf, name))
              or inspect.isclass(getattr(imgmtf, name))] + [f"plot.{name}" for name in imgmtf.plot.__all__])


def qualified(obj) -> str:
    return f"{obj.__module__}.{obj.__qualname__}"


def package_members():
    """Every public function, class and method defined in imgmtf's modules."""
    for info in pkgutil.walk_packages(imgmtf.__path__, "imgmtf."):
        if info.name.endswith("__main__"):
            continue
        module = importlib.import_module(info.name)
        for name, value in vars(module).items():
            if name.startswith("_") or getattr(value, "__module__", None) != info.name:
                continue
            if inspect.isfunction(value):
                yield f"{info.name}.{name}"
            elif inspect.isclass(value):
                yield f"{info.name}.{name}"
                for attribute, member in vars(value).items():
                    if not attribute.startswith("_") and (inspect.isfunction(member) or isinstance(
                            member, (property, classmethod, staticmethod))):
                        yield f"{info.name}.{name}.{attribute}"


def load(name: str):
    module, _, rest = name.partition(".")
    obj = importlib.import_module(module)
    for part in rest.split("."):
        try:
            obj = getattr(obj, part)
        except AttributeError:
            obj = importlib.import_module(f"{obj.__name__}.{part}")
    return obj


def problems(name: str, codes: set[str]) -> list[str]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")       # numpydoc warns of an unknown section as it reports GL06
        report = validate.validate(name)
        errors = [(code, message) for code, message in report["errors"] if code in codes]
        obj = load(name)
        if inspect.isclass(obj) and dataclasses.is_dataclass(obj):
            errors = dataclass_fields(obj, errors)
    return [f"{code} {message}" for code, message in errors]


def dataclass_fields(cls, errors):
    """A dataclass's fields are its parameters and its attributes at once;
    numpydoc looks for them under Parameters only (numpy/numpydoc#604), so
    one documented under Attributes counts, with a type and a description,
    as does one a dataclass it derives from documents.  A private field
    (``_model``) is the class's own business, not documented."""
    doc = docscrape.ClassDoc(cls, config={"show_class_members": False})
    inherited = [entry for base in cls.__mro__[1:] if dataclasses.is_dataclass(base)
                 for entry in docscrape.ClassDoc(base, config={"show_class_members": False})["Attributes"]]
    documented = {name.strip() for entry in doc["Parameters"] + doc["Attributes"] + inherited
                  for name in entry.name.split(",")}
    stars = {inspect.Parameter.VAR_POSITIONAL: "*", inspect.Parameter.VAR_KEYWORD: "**"}
    out = []
    for code, message in errors:
        if code == "PR01":
            missing = sorted(stars.get(p.kind, "") + p.name for p in inspect.signature(cls).parameters.values()
                             if stars.get(p.kind, "") + p.name not in documented and not p.name.startswith("_"))
            if not missing:
                continue
            message = f"Parameters {missing} not documented"
        out.append((code, message))
    for entry in doc["Attributes"]:
        if not entry.type:
            out.append(("PR04", f'Attribute "{entry.name}" has no type'))
        if not entry.desc:
            out.append(("PR07", f'Attribute "{entry.name}" has no description'))
    return out


def public(name: str):
    return load(f"imgmtf.{name}")


@pytest.mark.parametrize("name", API)
def test_the_public_api_documents_its_parameters_returns_and_examples(name):
    full = qualified(public(name))
    found = problems(full, SECTIONS_AND_TYPES)
    assert not found, f"{full}:\n" + "\n".join(found)


def test_every_docstring_with_sections_writes_them_as_numpydoc_reads_them():
    found = {name: problems(name, WRITTEN_RIGHT) for name in package_members()}
    found = {name: errors for name, errors in found.items() if errors}
    assert not found, "\n".join(f"{name}:\n  " + "\n  ".join(errors) for name, errors in found.items())


def test_the_public_classes_methods_document_their_parameters():
    """Every public method of a public class documents each parameter with
    its type (an example and a Returns section are asked of the API only)."""
    found = {}
    for name in API:
        cls = public(name)
        if not inspect.isclass(cls):
            continue
        for attribute, member in vars(cls).items():
            if attribute.startswith("_") or not (inspect.isfunction(member) or isinstance(
                    member, (property, classmethod, staticmethod))):
                continue
            method = f"{qualified(cls)}.{attribute}"
            found[method] = problems(method, WRITTEN_RIGHT | {"PR01"})
    found = {name: errors for name, errors in found.items() if errors}
    assert not found, "\n".join(f"{name}:\n  " + "\n  ".join(errors) for name, errors in found.items())


def unannotated(function) -> list[str]:
    signature = inspect.signature(function)
    missing = [p.name for p in signature.parameters.values()
               if p.name not in ("self", "cls") and p.annotation is inspect.Parameter.empty]
    if signature.return_annotation is inspect.Signature.empty and function.__name__ != "__init__":
        missing.append("return")
    return missing


def test_the_public_api_and_every_stage_are_annotated():
    """Type hints on the public functions, the public classes' methods (their
    constructor and call included) and every sensor stage's."""
    from imgmtf.sensor.stages import STAGES, Stage
    found = {}
    for obj in [public(name) for name in API] + [Stage, *STAGES.values()]:
        functions = [obj] if inspect.isfunction(obj) else [
            member for attribute, member in vars(obj).items()
            if inspect.isfunction(member) and (not attribute.startswith("_") or attribute in ("__init__", "__call__"))]
        for function in functions:
            missing = unannotated(function)
            if missing:
                found[qualified(function)] = missing
    assert not found, "\n".join(f"{name}: {', '.join(missing)}" for name, missing in found.items())

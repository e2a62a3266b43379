"""numpydoc's validation of the public API's docstrings (tests/docs/test_docs_docstrings.py).

Every function and class in the ``__all__`` of the packages the API reference documents
(:data:`generate.PACKAGES`) is checked for :data:`CHECKS`. A dataclass documents its fields
(its constructor's parameters) under ``Attributes``; an enum's constructor is the Enum
machinery's, not checked. ``numpydoc_outstanding.txt`` lists the names not brought to the
standard yet: the list only shrinks (a listed name that passes fails the test too).
"""

from __future__ import annotations

import enum
import importlib
import re
from pathlib import Path

import generate
from numpydoc.docscrape import get_doc_object
from numpydoc.validate import validate

#: every parameter documented (PR01) and none unknown (PR02), each with a description
#: (PR07), sections in numpydoc's order (GL07), a docstring at all (GL08)
CHECKS = {"PR01", "PR02", "PR07", "GL07", "GL08"}
OUTSTANDING = Path(__file__).with_name("numpydoc_outstanding.txt")
_ATTRIBUTES = re.compile(r"(?m)^\s*Attributes\s*$")


def outstanding() -> set[str]:
    """The names whose docstrings are not checked yet."""
    lines = OUTSTANDING.read_text().splitlines()
    return {ln.strip() for ln in lines if ln.strip() and not ln.startswith("#")}


def public_objects() -> dict[str, object]:
    """``package.name -> object`` for every function and class of the packages' ``__all__``
    (a name exported by two packages once, under the package that documents it)."""
    owners = generate._owners()
    out = {}
    for package in generate.PACKAGES:
        mod = importlib.import_module(package)
        for name in mod.__all__:
            obj = getattr(mod, name)
            if name.startswith("_") or not (callable(obj) or isinstance(obj, type)):
                continue
            if owners.get(id(obj), package) == package:
                out[f"{package}.{name}"] = obj
    return out


def errors(obj) -> list[tuple[str, str]]:
    """The :data:`CHECKS` that ``obj``'s docstring fails, as ``(code, message)``."""
    if isinstance(obj, type) and issubclass(obj, enum.Enum):
        return []
    found = validate(get_doc_object(obj))["errors"]
    skip_pr01 = bool(_ATTRIBUTES.search(getattr(obj, "__doc__", None) or ""))
    return [(c, m) for c, m in found if c in CHECKS and not (c == "PR01" and skip_pr01)]

"""The public API's docstrings pass numpydoc's validation (docs/tools/docstrings.py)."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "docs" / "tools"))

import docstrings

OBJECTS = docstrings.public_objects()
OUTSTANDING = docstrings.outstanding()


def test_public_docstrings_pass_numpydoc_validation():
    failing = {name: docstrings.errors(obj) for name, obj in OBJECTS.items() if name not in OUTSTANDING}
    failing = {name: errs for name, errs in failing.items() if errs}
    assert failing == {}, "document these (numpydoc: Parameters, Returns) " + repr(failing)


def test_the_outstanding_list_only_shrinks():
    fixed = sorted(n for n in OUTSTANDING if n in OBJECTS and not docstrings.errors(OBJECTS[n]))
    gone = sorted(n for n in OUTSTANDING if n not in OBJECTS)
    assert fixed == [] and gone == [], f"remove from numpydoc_outstanding.txt: {fixed + gone}"


def test_the_checks_catch_an_undocumented_parameter():
    def f(x, y):
        """Add.

        Parameters
        ----------
        x : float
            One.
        """

    assert [c for c, _ in docstrings.errors(f)] == ["PR01"]

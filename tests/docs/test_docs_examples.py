"""The ``Examples`` sections of the main entry points' docstrings run as written (doctest)."""

import doctest
import importlib

import pytest

#: the modules whose public docstrings show examples: kappa, streamlines, a preset,
#: build_rig and a run, a sweep, an I_e* estimate
MODULES = [
    "spine_mj.theory.engagement",
    "spine_mj.theory.streamline",
    "spine_mj.presets",
    "spine_mj.sim.build",
    "spine_mj.sweep.session",
    "spine_mj.validate.ie_star",
]


@pytest.mark.parametrize("name", MODULES)
def test_examples_run(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    module = importlib.import_module(name)
    tests = [t for t in doctest.DocTestFinder().find(module) if t.examples]
    assert tests, f"{name} shows no example"
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for test in tests:
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.attempted > 0 and result.failed == 0

"""Package layout only; all metadata is in pyproject.toml.

``models/`` and ``surfaces/`` stay at the repository's top level and ship inside the
package as ``spine_mj._data.models`` and ``spine_mj._data.surfaces``, the example scans of
``tests/data/`` and sweep configs of ``analysis/sweeps/`` as ``spine_mj._data.scans`` and
``spine_mj._data.sweeps`` (read through ``spine_mj.resources``). pyproject's
``packages.find`` cannot rename folders, so the package list is built here: every package
under ``spine_mj/`` that has an ``__init__.py`` (new subpackages are picked up
automatically) plus the mapped data packages.
"""

from setuptools import find_packages, setup

DATA = {
    "spine_mj._data.models": "models",
    "spine_mj._data.surfaces": "surfaces",
    # the README's examples (spine_mj.examples: `example:NAME`): two measured scans from
    # SurfaceTopography's MIT-licensed test suite (tests/data/README.md) and the sweep configs
    "spine_mj._data.scans": "tests/data",
    "spine_mj._data.sweeps": "analysis/sweeps",
}

setup(
    packages=[*find_packages(include=["spine_mj", "spine_mj.*"]), *DATA],
    package_dir=DATA,
    package_data={
        # the public names of each package (read by lazy_loader, type checkers and the docs)
        "": ["*.pyi"],
        "spine_mj": ["py.typed"],
        "spine_mj._data.models": ["*.xml"],
        "spine_mj._data.surfaces": ["*.toml"],
        "spine_mj._data.scans": ["*.plu", "*.di", "README.md"],
        "spine_mj._data.sweeps": ["*.toml"],
        "spine_mj.templates": ["*.j2"],
    },
)

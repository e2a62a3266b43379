"""Package layout only; all metadata is in pyproject.toml.

``models/`` and ``surfaces/`` stay at the repository's top level and ship inside the
package as ``spine_mj._data.models`` and ``spine_mj._data.surfaces`` (read through
``spine_mj.resources``). pyproject's ``packages.find`` cannot rename folders, so the
package list is built here: every package under ``spine_mj/`` that has an ``__init__.py``
(new subpackages are picked up automatically) plus the two mapped data packages.
"""

from setuptools import find_packages, setup

DATA = {"spine_mj._data.models": "models", "spine_mj._data.surfaces": "surfaces"}

setup(
    packages=[*find_packages(include=["spine_mj", "spine_mj.*"]), *DATA],
    package_dir=DATA,
    package_data={
        "spine_mj._data.models": ["*.xml"],
        "spine_mj._data.surfaces": ["*.toml"],
        "spine_mj.templates": ["*.j2"],
    },
)

"""The CLI is a shell: its modules parse arguments, call the library and print what it
returns. None imports pandas (tables are the library's), and none builds a rig, a drive or
a model itself (one library function per command does: ``simulate_to``, ``array_to``,
``export_rig``, ``view_rig``)."""

import ast
from pathlib import Path

import pytest

import spine_mj.cli

CLI_MODULES = sorted(Path(spine_mj.cli.__file__).parent.glob("*.py"))

#: What only the library may call: the rig, drive and model builders and the rigs' classes.
BUILDERS = {
    "build_rig",
    "build_engine_rig",
    "build_drive",
    "build_array",
    "build_array_on",
    "Rig",
    "RigModel",
    "ArrayRig",
    "BulletRig",
    "compile_spec",
}


def _names(tree: ast.AST) -> tuple[set[str], set[str]]:
    """The modules ``tree`` imports (at top level or in functions) and the names it uses."""
    modules, used = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            modules |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            modules.add(node.module or "")
            used |= {a.name for a in node.names}
        elif isinstance(node, ast.Name):
            used.add(node.id)
        elif isinstance(node, ast.Attribute):
            used.add(node.attr)
    return modules, used


def test_the_cli_modules_are_found():
    assert {p.stem for p in CLI_MODULES} >= {"app", "sim", "array", "theory", "sweep", "validate", "surface"}


@pytest.mark.parametrize("path", CLI_MODULES, ids=lambda p: p.name)
def test_no_cli_module_imports_pandas_or_builds_a_rig(path):
    modules, used = _names(ast.parse(path.read_text()))
    assert not {m for m in modules if m.split(".")[0] in {"pandas", "pyarrow"}}, path.name
    assert not used & BUILDERS, f"{path.name} builds {sorted(used & BUILDERS)} itself"


def test_the_check_sees_a_rig_built_in_a_command():
    # the same check on a command that builds its rig, as simulate did before it was a shell
    code = "def simulate(spec):\n    from spine_mj import sim\n    rig = sim.build_rig(spec, mu=1)\n"
    assert _names(ast.parse(code))[1] & BUILDERS == {"build_rig"}
    assert "pandas" in _names(ast.parse("def f():\n    import pandas as pd\n"))[0]

"""The CLI is a shell: its modules parse arguments, call the library and print what it
returns. None imports pandas (tables are the library's), none builds a rig, a drive or
a model itself (one library function per command does: ``simulate_to``, ``array_to``,
``export_rig``, ``view_rig``), and every command makes one call into the library besides
those that parse its arguments or format what it returns for printing."""

import ast
from pathlib import Path

import pytest

import spine_mj.cli

CLI_MODULES = sorted(Path(spine_mj.cli.__file__).parent.glob("*.py"))

#: What only the library may call: the rig, drive and model builders and the rigs' classes.
BUILDERS = {
    "build_rig",
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


#: Calls into the library that parse the command line rather than do the command's work:
#: a SURFACE, example or CONFIG argument opened, the one mu and tip rules, argument checks
#: (``check_*``, ``parse_*``, ``has_*``) and parameter records or errors (classes); and
#: what formats a returned value for printing (``*_lines``).
PARSING = {"open_surface", "resolve", "resolve_mu", "resolve_tip_radius", "preset_mu", "load_config"}


def _is_parsing_or_printing(name: str) -> bool:
    return (
        name in PARSING
        or name.startswith(("check_", "parse_", "has_"))
        or name.endswith("_lines")
        or name[:1].isupper()
    )


def _library_names(nodes) -> set[str]:
    """The names that the import statements among ``nodes`` bind to the library (``spine_mj``
    but not its CLI): its modules and its functions."""
    return {
        alias.asname or alias.name
        for node in nodes
        if isinstance(node, ast.ImportFrom)
        and (node.module or "").startswith("spine_mj")
        and not node.module.startswith("spine_mj.cli")
        for alias in node.names
    }


def _commands(tree: ast.Module) -> list[ast.FunctionDef]:
    """The functions of a CLI module registered as commands (``@<group>.command(...)``)."""
    return [
        node
        for node in tree.body
        if isinstance(node, ast.FunctionDef)
        and any(".command(" in ast.unparse(d) for d in node.decorator_list)
    ]


def library_calls(tree: ast.Module, command: ast.FunctionDef) -> list[str]:
    """The calls into the library that ``command`` makes itself (helpers of its CLI module
    are the parsing), but for those that parse or print (:func:`_is_parsing_or_printing`)."""
    library = _library_names(tree.body) | _library_names(ast.walk(command))
    calls = []
    for node in ast.walk(command):
        if not isinstance(node, ast.Call):
            continue
        f = node.func
        if isinstance(f, ast.Name) and f.id in library:  # a function: f(...)
            calls.append(f.id)
        elif isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) and f.value.id in library:
            calls.append(f.attr)  # a module's function: module.f(...)
    return [c for c in calls if not _is_parsing_or_printing(c)]


COMMANDS = [
    (path, command.name) for path in CLI_MODULES for command in _commands(ast.parse(path.read_text()))
]


def test_every_command_is_found():
    names = {name for _, name in COMMANDS}
    assert {"kappa_cmd", "surface_make", "surface_info", "surface_show", "replay", "reproduce_cmd"} <= names
    assert {"simulate", "array_cmd", "sim_export", "view", "sweep_run", "validate_cmd"} <= names
    assert len(COMMANDS) >= 18


@pytest.mark.parametrize(("path", "name"), COMMANDS, ids=[f"{p.stem}:{n}" for p, n in COMMANDS])
def test_every_command_makes_one_call_into_the_library(path, name):
    tree = ast.parse(path.read_text())
    (command,) = [c for c in _commands(tree) if c.name == name]
    calls = library_calls(tree, command)
    assert len(calls) == 1, f"{path.name}:{name} calls {calls}: its work belongs in one library function"


def test_the_count_sees_a_command_that_assembles_its_result():
    # kappa as it was before it was a shell: the grid, the figure and its saving
    code = """
@main.command("kappa")
def kappa_cmd(spec, mu, output, resolution):
    from spine_mj import presets
    from spine_mj.plotting import kappa_map_figure, save_figure
    from spine_mj.theory import engagement

    check_suffix(output, ".png", "-o/--output")
    surf = presets.open_surface(spec)
    mu = presets.resolve_mu(surf, mu, name="--mu")
    xs, _, heights, k, region = engagement.kappa_grid(surf, mu, resolution)
    save_figure(kappa_map_figure({"s": (xs, heights, k, region)}, mu), output)
"""
    tree = ast.parse(code)
    (command,) = _commands(tree)
    assert sorted(library_calls(tree, command)) == ["kappa_grid", "kappa_map_figure", "save_figure"]

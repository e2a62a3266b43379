"""The public API: every exported name resolves, and the analytic side needs no MuJoCo."""

import ast
import subprocess
import sys
from pathlib import Path

import spine_mj


def test_every_exported_name_resolves():
    for name in spine_mj.__all__:
        assert getattr(spine_mj, name) is not None, name


def test_analytic_side_imports_without_mujoco():
    code = "import sys, spine_mj; spine_mj.streamlines; spine_mj.kappa; print('mujoco' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


#: Module paths the package served through an import hook before the theory package and
#: the agreement metrics got their homes: they are gone, not aliased.
OLD_PATHS = (
    "spine_mj.engagement",
    "spine_mj.streamline",
    "spine_mj.drive_limits",
    "spine_mj._contact_kernel",
    "spine_mj.array_outputs",
    "spine_mj.sim.motion",
    "spine_mj.compare",
    "spine_mj.sim.params",
    "spine_mj.sim.planes",
)


def test_importing_the_package_installs_no_import_hook():
    code = """
import sys
hooks = list(sys.meta_path)
import spine_mj
assert sys.meta_path == hooks, sys.meta_path
import spine_mj.sim, spine_mj.sweep, spine_mj.validate
ours = [f for f in sys.meta_path if type(f).__module__.startswith("spine_mj")]
assert ours == [], ours
"""
    subprocess.run([sys.executable, "-c", code], check=True)


def test_the_old_module_paths_are_gone():
    root = Path(spine_mj.__file__).parent.parent
    left = [old for old in OLD_PATHS if (root / (old.replace(".", "/") + ".py")).exists()]
    assert left == []
    assert not hasattr(spine_mj, "MOVED")


def _is_reexport_only(tree: ast.Module) -> bool:
    """True when a module's body is nothing but a docstring, imports and ``__all__``."""
    body = [n for n in tree.body if not (isinstance(n, ast.Expr) and isinstance(n.value, ast.Constant))]
    imports = [n for n in body if isinstance(n, (ast.Import, ast.ImportFrom))]
    rest = [
        n
        for n in body
        if not isinstance(n, (ast.Import, ast.ImportFrom))
        and not (isinstance(n, ast.Assign) and [getattr(t, "id", "") for t in n.targets] == ["__all__"])
    ]
    return bool(imports) and not rest


def test_no_module_only_reexports_another():
    # a package's __init__ may gather its public names; a plain module must define something
    root = Path(spine_mj.__file__).parent
    shims = [
        str(path.relative_to(root.parent))
        for path in root.rglob("*.py")
        if path.name != "__init__.py" and _is_reexport_only(ast.parse(path.read_text()))
    ]
    assert shims == []


def test_no_module_imports_a_name_as_itself():
    # ``from a import b as b`` is how a module re-exports a name it does not use
    root = Path(spine_mj.__file__).parent
    found = [
        f"{path.relative_to(root.parent)}:{node.lineno} {alias.name}"
        for path in root.rglob("*.py")
        if path.name != "__init__.py"
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.ImportFrom)
        for alias in node.names
        if alias.asname == alias.name
    ]
    assert found == []


def test_submodules_resolve_as_attributes_of_the_package():
    code = "import sys, spine_mj; print(spine_mj.theory is sys.modules['spine_mj.theory'])"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "True"


def test_shipped_files_are_found_through_the_package():
    # models/ and surfaces/ ship as spine_mj._data.* (setup.py), found by spine_mj.resources
    # in an editable install and in a wheel alike (`make wheel-check` covers the wheel)
    from spine_mj import presets, resources

    assert resources.model_path().is_file()
    assert resources.model_path().name == "spine_rig.xml"
    names = {p.stem for p in resources.presets_dir().glob("*.toml")}
    assert {"paper-single-peak", "paper-single-valley", "paper-fractal"} <= names
    assert set(presets.list_presets()) == names


def _stub_homes(root: Path) -> dict[str, dict[str, str]]:
    """Package -> {public name: the module it loads from}, read from the package's
    ``__init__.pyi`` (what ``lazy_loader.attach_stub`` imports on first use of the name)."""
    homes = {}
    for stub in root.rglob("__init__.pyi"):
        package = ".".join(stub.parent.relative_to(root.parent).parts)
        homes[package] = {
            alias.asname or alias.name: f"{package}.{node.module}"
            if node.module
            else f"{package}.{alias.name}"
            for node in ast.parse(stub.read_text()).body
            if isinstance(node, ast.ImportFrom)
            for alias in node.names
        }
    return homes


def _package_imports() -> dict[str, set[str]]:
    """Module name -> the spine_mj modules it imports (at top level or inside functions); a
    name taken from a package with a stub is an arrow to the module the stub loads it from,
    and the package itself has an arrow to every module its stub names."""
    root = Path(spine_mj.__file__).parent
    modules = {}
    for path in root.rglob("*.py"):
        parts = path.relative_to(root.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        modules[name] = path
    homes = _stub_homes(root)
    graph = {}
    for name, path in modules.items():
        is_pkg = path.name == "__init__.py"
        package = name if is_pkg else name.rpartition(".")[0]
        edges = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                    base = f"{anchor}.{base}" if base else anchor
                targets = [
                    f"{base}.{a.name}"
                    if f"{base}.{a.name}" in modules
                    else homes.get(base, {}).get(a.name, base)
                    for a in node.names
                ]
            else:
                continue
            edges |= {t for t in targets if t in modules and t != name}
        # a package with a stub loads its names on first use: an arrow to each of their modules
        edges |= {m for m in homes.get(name, {}).values() if m in modules and m != name}
        graph[name] = edges
    return graph


def test_no_module_imports_one_that_imports_it_back():
    graph = _package_imports()
    cycles = []
    state: dict[str, int] = {}

    def visit(node, stack):
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                cycles.append([*stack[stack.index(nxt) :], nxt])
            elif nxt not in state:
                visit(nxt, stack)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [])
    assert not cycles, "import cycles: " + "; ".join(" -> ".join(c) for c in cycles)


#: What the theory may import: itself, the surfaces and the flat foundation modules.
THEORY_MAY_IMPORT = ("theory", "surfaces", "errors", "memory", "atomic", "roughness", "plotting", "jsonio")


def test_the_theory_imports_nothing_above_it():
    graph = _package_imports()
    theory = sorted(m for m in graph if m == "spine_mj.theory" or m.startswith("spine_mj.theory."))
    assert "spine_mj.theory.streamline" in theory
    upward = {
        m: sorted(e for e in graph[m] if e != "spine_mj" and e.split(".")[1] not in THEORY_MAY_IMPORT)
        for m in theory
    }
    assert not any(upward.values()), upward
    code = (
        "import sys, spine_mj.theory, pkgutil, importlib\n"
        "for m in pkgutil.iter_modules(spine_mj.theory.__path__):\n"
        "    importlib.import_module('spine_mj.theory.' + m.name)\n"
        "print(sorted(n for n in sys.modules if n == 'mujoco' or n.startswith(('mujoco.', 'spine_mj.sim'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_the_packages_import_together():
    code = "import spine_mj.sweep, spine_mj.sim, spine_mj.validate"
    subprocess.run([sys.executable, "-c", code], check=True)


#: The most lines a module and a function may have (numba kernels aside: a compiled loop
#: is one unit, however long).
MAX_MODULE_LINES, MAX_FUNCTION_LINES = 600, 80


def _is_numba_kernel(node: ast.FunctionDef) -> bool:
    return any(
        any(word in ast.unparse(d) for word in ("jit", "numba", "vectorize")) for d in node.decorator_list
    )


def test_no_module_or_function_is_too_long():
    root = Path(spine_mj.__file__).parent
    long_modules, long_functions = {}, {}
    for path in sorted(root.rglob("*.py")):
        name = path.relative_to(root.parent).as_posix()
        text = path.read_text()
        if text.count("\n") > MAX_MODULE_LINES:
            long_modules[name] = text.count("\n")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and not _is_numba_kernel(node):
                lines = node.end_lineno - node.lineno + 1  # docstring included
                if lines > MAX_FUNCTION_LINES:
                    long_functions[f"{name}:{node.name}"] = lines
    assert not long_modules, f"modules over {MAX_MODULE_LINES} lines: {long_modules}"
    assert not long_functions, f"functions over {MAX_FUNCTION_LINES} lines: {long_functions}"


#: The most modules directly in spine_mj/ (the rest live in its packages).
MAX_FLAT_MODULES = 15


def test_the_top_of_the_package_holds_at_most_15_flat_modules():
    root = Path(spine_mj.__file__).parent
    flat = sorted(p.stem for p in root.glob("*.py") if p.name != "__init__.py")
    assert "jsonio" in flat and "streamline" not in flat
    assert len(flat) <= MAX_FLAT_MODULES, flat


def test_the_tests_mirror_the_surfaces_package_and_the_modules_once_untested():
    root, tests = Path(spine_mj.__file__).parent, Path(__file__).parent
    surfaces = [p.stem.lstrip("_") for p in (root / "surfaces").glob("*.py") if p.name != "__init__.py"]
    assert len(surfaces) >= 9
    missing = [s for s in surfaces if not (tests / "surfaces" / f"test_surfaces_{s}.py").is_file()]
    assert not missing, f"surfaces modules without a test module: {missing}"
    direct = ["sim/test_sim_array_outputs.py", "test_jsonio.py", "test_workers.py"]
    direct += ["surfaces/test_surfaces_contact_kernel.py", "validate/report/test_validate_report_document.py"]
    assert all((tests / d).is_file() for d in direct), [d for d in direct if not (tests / d).is_file()]


def test_each_public_package_lists_its_names_in_its_stub_at_their_homes():
    """One form of the public API: a package's ``__all__`` is its stub's names, each class and
    function named at the module that defines it (what type checkers and the docs read), and
    importing the package imports none of its modules (the sweep's registering analyses
    aside)."""
    import importlib
    import inspect

    root = Path(spine_mj.__file__).parent
    homes = _stub_homes(root)
    assert set(homes) >= {
        "spine_mj",
        "spine_mj.surfaces",
        "spine_mj.sim",
        "spine_mj.sweep",
        "spine_mj.validate",
    }
    for package, names in homes.items():
        mod = importlib.import_module(package)
        assert sorted(mod.__all__) == sorted(names), package
        for name, home in names.items():
            obj = getattr(mod, name)
            if inspect.ismodule(obj):
                assert obj.__name__ == home, (package, name)
            elif inspect.isclass(obj) or inspect.isfunction(obj):
                assert obj.__module__ == home, (package, name, obj.__module__)
    code = (
        "import sys, spine_mj.sim, spine_mj.validate, spine_mj.surfaces\n"
        "print(sorted(n for n in sys.modules if n.startswith('spine_mj.') and n.count('.') > 1))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"

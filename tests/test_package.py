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


#: Every module that moved, by its old public path, and a name each one exports.
OLD_PATHS = {
    "spine_mj.engagement": ("spine_mj.theory.engagement", "kappa"),
    "spine_mj.streamline": ("spine_mj.theory.streamline", "StreamlineParams"),
    "spine_mj.compliant": ("spine_mj.theory.compliant", "compliant_streamlines"),
    "spine_mj.convexity": ("spine_mj.theory.convexity", "hessian_class"),
    "spine_mj.multicontact": ("spine_mj.theory.multicontact", "two_contact_kappa"),
    "spine_mj.tomlinson": ("spine_mj.theory.tomlinson", "Corrugation"),
    "spine_mj.tomlinson_dynamics": ("spine_mj.theory.tomlinson_dynamics", "integrate"),
    "spine_mj.drive_limits": ("spine_mj.theory.drive_limits", "drive_limits"),
    "spine_mj.energy": ("spine_mj.theory.energy", "elastic_release_j"),
    "spine_mj.array_reference": ("spine_mj.theory.array_reference", "summed_curve"),
    "spine_mj._kernels": ("spine_mj.theory._kernels", "run_trajectories"),
    "spine_mj._compliant_kernel": ("spine_mj.theory._compliant_kernel", "fold_on_facets"),
    "spine_mj._contact_kernel": ("spine_mj.surfaces._contact_kernel", "ball_on_facets"),
    "spine_mj.array_outputs": ("spine_mj.sim.array_outputs", "write_array_outputs"),
    "spine_mj.sim.motion": ("spine_mj.theory.motion", "slip_events"),
}


def test_every_old_import_path_still_works():
    # in a fresh interpreter, so that no earlier import has loaded a module by its new name
    code = f"""
import importlib, sys
for old, (new, name) in {OLD_PATHS!r}.items():
    package, _, leaf = old.rpartition(".")
    by_path, by_name, by_package = {{}}, {{}}, {{}}
    exec(f"import {{old}}", by_path)
    exec(f"from {{old}} import {{name}}", by_name)
    exec(f"from {{package}} import {{leaf}}", by_package)
    home = sys.modules[new]
    assert home.__name__ == new and sys.modules[old] is home and by_package[leaf] is home, old
    assert eval(old, by_path) is home and by_name[name] is getattr(home, name), old
"""
    subprocess.run([sys.executable, "-c", code], check=True)


def test_old_module_names_resolve_as_attributes_of_the_package():
    code = "import spine_mj; print(spine_mj.streamline.streamlines is spine_mj.streamlines)"
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


def _package_imports() -> dict[str, set[str]]:
    """Module name -> the spine_mj modules it imports (at top level or inside functions)."""
    root = Path(spine_mj.__file__).parent
    modules = {}
    for path in root.rglob("*.py"):
        parts = path.relative_to(root.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        modules[name] = path
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
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names]
            else:
                continue
            edges |= {t for t in targets if t in modules and t != name}
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


def test_the_theory_imports_neither_mujoco_nor_the_sim():
    graph = _package_imports()
    theory = sorted(m for m in graph if m == "spine_mj.theory" or m.startswith("spine_mj.theory."))
    assert "spine_mj.theory.streamline" in theory
    upward = {
        m: sorted(e for e in graph[m] if e.split(".")[1] in {"sim", "sweep", "validate", "cli"})
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

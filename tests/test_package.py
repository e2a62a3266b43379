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


def test_the_packages_import_together():
    code = "import spine_mj.sweep, spine_mj.sim, spine_mj.validate"
    subprocess.run([sys.executable, "-c", code], check=True)

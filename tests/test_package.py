"""The public API: every exported name resolves, and the analytic side needs no MuJoCo."""

import subprocess
import sys

import spine_mj


def test_every_exported_name_resolves():
    for name in spine_mj.__all__:
        assert getattr(spine_mj, name) is not None, name


def test_analytic_side_imports_without_mujoco():
    code = "import sys, spine_mj; spine_mj.streamlines; spine_mj.kappa; print('mujoco' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"

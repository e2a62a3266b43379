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


def test_shipped_files_are_found_through_the_package():
    # models/ and surfaces/ ship as spine_mj._data.* (setup.py), found by spine_mj.resources
    # in an editable install and in a wheel alike (`make wheel-check` covers the wheel)
    from spine_mj import presets, resources

    assert resources.model_path().is_file()
    assert resources.model_path().name == "spine_rig.xml"
    names = {p.stem for p in resources.presets_dir().glob("*.toml")}
    assert {"paper-single-peak", "paper-single-valley", "paper-fractal"} <= names
    assert set(presets.list_presets()) == names

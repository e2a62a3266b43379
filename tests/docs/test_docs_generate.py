"""The pages written from the data at build time (docs/tools/generate.py)."""

import copy
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "docs" / "tools"))

import generate  # noqa: E402

FULL = generate.load_validation("validation-full")


def test_committed_plans_render():
    for plan, folder, command in generate.PLANS:
        validation = generate.load_validation(folder)
        page = generate.results_page(plan, folder, command, validation)
        for family in validation["limit_families"]:
            assert generate.FAMILY_NAMES.get(family, family) in page
        assert f"reports/{folder}/report.md" in page


def test_headline_table_numbers_are_the_json_numbers():
    """Each headline is quoted where its own refinements left it inside its interval, and
    only there; a family with an unconverged headline gets no target verdict."""
    rows = generate.headline_table(FULL)
    assert len(rows) == 2 + len(FULL["limit_families"])
    quoted = 0
    for name, fam in FULL["limit_families"].items():
        row = next(r for r in rows if r.startswith(f"| {generate.FAMILY_NAMES.get(name, name)} |"))
        cells = [c.strip() for c in row.strip("|").split("|")]
        levels = (FULL.get("convergence") or {}).get(name) or {}
        for headline, cell, number in (
            ("agreement_well_conditioned", cells[2], f"{fam['agreement_well_conditioned']:.3g}"),
            ("median_frechet", cells[4], f"{fam['median_frechet_ci'][1]:.3g}"),
        ):
            moved = any(
                isinstance(v, dict) and v.get(f"{headline}_converged") is False for v in levels.values()
            )
            assert cell.startswith("not quoted (unconverged: ") is moved
            if not moved:
                quoted += 1
                assert number in cell
        family_moved = any(isinstance(v, dict) and v.get("converged") is False for v in levels.values())
        assert (cells[5] == "no verdict") is family_moved
    assert quoted


def test_convergence_absent_renders_nothing():
    stripped = {k: v for k, v in FULL.items() if k != "convergence"}
    for s in stripped["limit_families"].values():
        s.pop("convergence", None)
    assert generate.convergence_section(stripped) == []
    assert "Convergence" not in generate.results_page("full", "validation-full", "x", stripped)


@pytest.mark.parametrize("where", ["top", "family"])
def test_convergence_present_is_rendered(where):
    check = {
        "dt_halved": {"agreement_change": -0.02, "median_frechet_change": 0.0011, "converged": True},
        "hfield_doubled": {"agreement_change": 0.05, "median_frechet_change": -0.004, "converged": False},
    }
    v = copy.deepcopy(FULL)
    if where == "top":
        v["convergence"] = {"fractal": check, "sandpaper": check}
    else:  # the per-family record, read where validation.json has no top-level one
        v.pop("convergence", None)
        v["limit_families"]["fractal"]["convergence"] = check
    lines = generate.convergence_section(v)
    text = "\n".join(lines)
    assert "dt_halved" in text and "hfield_doubled" in text
    assert "-0.02" in text and "0.0011" in text and "True" in text and "False" in text
    assert "| fractal | dt_halved |" in text


def test_every_public_name_is_on_one_api_page(tmp_path):
    generate.api_pages(tmp_path)
    text = {p.stem: p.read_text() for p in tmp_path.glob("*.rst")}
    import importlib

    for package in generate.PACKAGES:
        for name in generate.public_names(importlib.import_module(package)):
            assert f"   {name}\n" in text[package] or f"{name}`" in text[package], f"{package}.{name}"


def test_the_i_e_star_and_static_blocks_are_the_studies_own_with_the_json_numbers(monkeypatch):
    """The page's I_e* table and static line come from the boundary and static studies' report
    modules (``results_lines``) and hold the JSON numbers; a study registered with a block of
    its own shows it after theirs, with no other file touched."""
    import types

    from spine_mj.validate import studies

    page = generate.results_page("full", "validation-full", "x", FULL)
    rows = page.splitlines()
    for drive, s in FULL["ie_star"].items():
        row = next(r for r in rows if r.startswith(f"| {drive} | "))
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[1] == s["criterion"] and cells[2] == f"{s['value']:.3g}"
        assert cells[4] == f"[{s['ci_low']:.3g}, {s['ci_high']:.3g}]"
    static = (
        f"over the engaged planes: {FULL['static_kappa_max_rel_error']:.3g} (`static_kappa_max_rel_error`)."
    )
    assert static in page
    assert page.index("## Where the quasistatic picture breaks") < page.index("## Static breakaway")
    report = types.SimpleNamespace(results_lines=lambda v: ["## Creep", "", f"rate {v['creep']} per s", ""])
    creep = studies.Study("creep", lambda plan, runner: None, type(None), report)
    monkeypatch.setattr(studies, "STUDIES", (*studies.STUDIES, creep))
    page = generate.results_page("full", "validation-full", "x", {**FULL, "creep": 0.25})
    assert "## Creep\n\nrate 0.25 per s\n" in page
    assert page.index("## Static breakaway") < page.index("## Creep")

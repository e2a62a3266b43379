"""The validation's headline lines, read from the committed full and quick results."""

import json
import re
from pathlib import Path

import pytest

from spine_mj.validate.report.common import corner_text
from spine_mj.validate.summary import summary_lines

REPORTS = Path(__file__).parents[2] / "analysis" / "reports"


@pytest.mark.parametrize("plan", ["validation-full", "validation-quick"])
def test_summary_lines_state_the_headline_numbers(plan):
    result = json.loads((REPORTS / plan / "validation.json").read_text())
    lines = summary_lines(result)
    static = [line for line in lines if line.startswith("static kappa max rel. error")]
    assert static == [
        f"static kappa max rel. error (engaged, default settings): {result['static_kappa_max_rel_error']:.3g}"
    ]
    # each family at its own corner (a report made before the corners: the fixed I_e, K = 30)
    corners = result.get("corner") or {
        key: {"ie": result["lowest_ie"], "K": 30} for key in result["limit_families"]
    }
    families = [
        line
        for line in lines
        if any(line.startswith(f"I_e, K = {corner_text(c)}, {f}: ") for f, c in corners.items())
    ]
    assert len(families) == len(result["limit_families"])
    for (fam, summ), line in zip(result["limit_families"].items(), families, strict=True):
        # a number that moved under refinement carries its mark (validate.convergence)
        agreement = re.escape(f", {fam}: outcome agreement {summ['outcome_agreement']:.0%}")
        assert re.search(agreement + rf"( \(unconverged: [^)]*\))? of {summ['runs']},", line), line
    for proto, star in result["ie_star"].items():
        assert any(line.startswith(f"I_e* ({proto})") for line in lines), proto
        if star.get("kind") == "bracketed":
            head = re.escape(f"  I_e* = {star['value']:.3g} in [{star['low']:.3g}, {star['high']:.3g}]")
            # a refined I_e* says whether it held (the full plan's boundary_refinements)
            assert any(re.fullmatch(head + r"( \((un)?converged: [^)]*\))?", x) for x in lines), head
    assert all("\n" not in line for line in lines)


def test_a_plan_without_the_optional_studies_gives_no_line_for_them():
    result = json.loads((REPORTS / "validation-full" / "validation.json").read_text())
    bare = {k: v for k, v in result.items() if k not in ("fractal_lock_rate", "arrays")}
    lines = summary_lines(bare)
    assert not any(line.startswith(("fractal self-lock", "arrays:")) for line in lines)
    assert len(lines) < len(summary_lines(result)) or not (
        result.get("fractal_lock_rate") or result.get("arrays")
    )


def test_a_new_studys_lines_and_numbers_come_from_its_own_report_module(monkeypatch):
    """A study registered with a report module that states its summary line and headline
    number shows in both, after the registry's studies, with no other file touched."""
    import types

    from spine_mj.validate import studies
    from spine_mj.validate.headlines import headline_numbers
    from spine_mj.validate.report.common import Headline

    result = json.loads((REPORTS / "validation-quick" / "validation.json").read_text())
    report = types.SimpleNamespace(
        summary_lines=lambda v: [f"creep: {v['creep']['rate']:.2g} per s"],
        headline_numbers=lambda v: {"creep.rate": Headline("creep.rate", v["creep"]["rate"], (0.0, 0.5))},
    )
    before_lines, before_numbers = summary_lines(result), headline_numbers(result)
    creep = studies.Study("creep", lambda plan, runner: None, type(None), report)
    monkeypatch.setattr(studies, "STUDIES", (*studies.STUDIES, creep))
    result["creep"] = {"rate": 0.25}
    assert summary_lines(result) == [*before_lines, "creep: 0.25 per s"]
    numbers = headline_numbers(result)
    assert list(numbers) == [*before_numbers, "creep.rate"] and numbers["creep.rate"].value == 0.25
    # a study whose report module states neither adds nothing
    monkeypatch.setattr(
        studies, "STUDIES", (*studies.STUDIES[:-1], studies.Study("bare", None, type(None), object()))
    )
    assert summary_lines(result) == before_lines and headline_numbers(result) == before_numbers

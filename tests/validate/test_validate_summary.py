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
    assert lines[0].endswith(f"{result['static_kappa_max_rel_error']:.3g}")
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

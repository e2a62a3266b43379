"""The static map's section of the report (report/static_map.py): the per-plane table with
its refinements, contacts, convergence and cause, and the summary line."""

from spine_mj.validate import StaticMapResult
from spine_mj.validate.report.common import ReportContext
from spine_mj.validate.report.static_map import section, summary_lines


def _plane(slope, error, converged, cause):
    return {
        "slope_deg": slope,
        "azimuth_deg": 0.0,
        "kappa": 1.0,
        "error_kind": "relative",
        "kappa_mj": 1.0 + error,
        "error": error,
        "abs_error_fp": error,
        "force_step_fp": 0.0016,
        "breakaway_contacts": 2,
        "held_contacts": 2,
        "contact_tilt_deg": 1.8,
        "contacts_lock_kappa": 1.2,
        "first_slip_kappa": 1.0,
        "slid_before_r_tip": 0.05,
        "kappa_mj_hfield_doubled": 1.0 + error,
        "error_hfield_doubled": error,
        "kappa_mj_hfield_quadrupled": 1.0,
        "error_hfield_quadrupled": 0.0,
        "change_hfield": -error,
        "tolerance_hfield": 0.0057,
        "converged": converged,
        "cause": cause,
    }


def test_the_section_tables_each_plane_with_its_cause_and_the_summary_counts_them(tmp_path):
    planes = [_plane(22.5, 0.001, True, "-"), _plane(52.5, 0.056, False, "recommended: edge catch: slipped")]
    st = StaticMapResult(rows=[], per_engine={}, mu=0.5, static_kappa_max_rel_error=0.056, planes=planes)
    ctx = ReportContext(out=tmp_path, figures=tmp_path / "figures", results={})
    text = section(st, ctx)
    assert "### Per plane" in text
    assert "| hfield x 2 | hfield x 4 |" in text
    rows = [line for line in text.splitlines() if line.startswith("| 52.5 |")]
    assert len(rows) == 1 and "| no | recommended: edge catch: slipped |" in rows[0]
    assert "1 of 2 engaged planes converged; 1 with an edge catch" in text
    lines = summary_lines({"static_kappa_max_rel_error": 0.056, **st.validation_keys()})
    assert lines[0] == "static kappa max rel. error (engaged, default settings): 0.056"
    assert lines[1].startswith(
        "static kappa per plane: largest error 0.056 (relative, absolute below kappa 0.268)"
    )
    assert lines[1].endswith("1 of 2 planes converged; 1 edge catches")
    # a report made before the per-plane table has the one line
    assert summary_lines({"static_kappa_max_rel_error": 0.056}) == [lines[0]]


def test_the_results_page_gains_the_per_plane_verdict_where_the_report_has_it():
    from spine_mj.validate.report.static_map import results_lines

    summ = {"error_rule": "R", "max_error": 0.0556, "planes": 33, "converged_planes": 22, "edge_catches": 6}
    old = results_lines({"static_kappa_max_rel_error": 0.0556})
    new = results_lines({"static_kappa_max_rel_error": 0.0556, "static_plane_summary": summ})
    assert new[: len(old)] == old
    assert new[len(old)].startswith("Per plane (R): largest error 0.0556; 22 of 33 engaged planes converged")

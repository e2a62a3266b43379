"""The validation's Markdown report (report/document.py): links only to written figures,
names its plan, shows counts beside rates."""

from report_links import assert_links_resolve

from spine_mj.validate import write_report as write_validation_report


def test_validation_report_links_only_written_figures_and_names_its_plan(tmp_path, validation_results):
    result = {"plan": "quick", "static_kappa_max_rel_error": 0.01, "engine_settings": {"dt": 1e-3}}
    result["timings_s"] = {"static": 1.23456}
    path = write_validation_report(tmp_path, result, validation_results.values())
    text = path.read_text()
    assert text.startswith("# Validation") and "(quick plan)" in text and "full plan" in text
    assert "{{" not in text and "{%" not in text
    assert_links_resolve(text, tmp_path)
    assert "figures/boundary.png" in text and "figures/limit_paths.png" in text
    assert "sandpaper.png" not in text and not (tmp_path / "figures" / "sandpaper.png").exists()
    assert "9/10" in text  # agree / runs beside the agreement
    assert "penetration 1" in text  # the engine stops of a family, by kind
    assert "stalled (single_peak_valley 2 of 10)" in text  # and the model's own stops
    assert "the issue" not in text

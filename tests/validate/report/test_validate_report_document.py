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


def _headline_list(text: str) -> list[str]:
    """The bullet lines under the report's headline heading."""
    part = text.split("## Where MuJoCo stops following the streamline: I_e*", 1)[1].split("\n## ", 1)[0]
    return [line for line in part.splitlines() if line.startswith("- ")]


def test_a_studys_headline_lines_are_its_report_modules_own(monkeypatch, tmp_path, validation_results):
    """A study registered with a report module that states headline lines shows them after the
    registry's studies' lines, and its section after theirs; a report module without
    ``headline`` adds no line."""
    import dataclasses
    import types

    from spine_mj.validate import studies

    @dataclasses.dataclass(frozen=True)
    class CreepResult:
        rate: float

    result = {"plan": "quick", "engine_settings": {}, "timings_s": {}}
    before = _headline_list(
        write_validation_report(tmp_path / "a", result, validation_results.values()).read_text()
    )
    assert before and all("I_e*" in line for line in before)
    report = types.SimpleNamespace(
        section=lambda res, ctx: f"## Creep\n\nrate {res.rate} per s\n",
        headline=lambda res: [f"creep: {res.rate} per s"],
    )
    creep = studies.Study("creep", lambda plan, runner: None, CreepResult, report)
    monkeypatch.setattr(studies, "STUDIES", (*studies.STUDIES, creep))
    results = [*validation_results.values(), CreepResult(0.25)]
    text = write_validation_report(tmp_path / "b", result, results).read_text()
    assert _headline_list(text) == [*before, "- creep: 0.25 per s"]
    assert text.index("## Creep") > text.index("## Where MuJoCo stops following the streamline")
    bare = studies.Study("creep", creep.run, CreepResult, types.SimpleNamespace(section=report.section))
    monkeypatch.setattr(studies, "STUDIES", (*studies.STUDIES[:-1], bare))
    text = write_validation_report(tmp_path / "c", result, results).read_text()
    assert _headline_list(text) == before and "rate 0.25 per s" in text

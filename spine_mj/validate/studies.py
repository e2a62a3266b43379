"""The registry of the validation's studies: what runs, in which order, and who reports it.

Each :class:`Study` names its run function (``(plan, runner) -> result``), the type of
its result (whose ``validation_keys()`` are its keys of ``validation.json``) and its
report module (:mod:`spine_mj.validate.report`). :func:`spine_mj.validate.run_validation`
runs the studies in this order and :func:`spine_mj.validate.write_report` puts their
sections into ``report.md`` in the same order; the lines ``spine-mj validate`` prints
(:func:`spine_mj.validate.summary.summary_lines`) and the headline numbers a reproduction
is checked on (:func:`spine_mj.validate.headlines.headline_numbers`) are the studies' own, in
the same order too, as are the blocks of the site's results pages (``docs/tools/generate.py``).
A new study is one study module, one report module and one line here
(``docs/developer/layout.md``, "Adding a study").
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import Any

from spine_mj.validate.array_study import ArrayStudyResult, array_study
from spine_mj.validate.boundary import BoundaryResult, boundary
from spine_mj.validate.engines import EnginesResult, engines_study
from spine_mj.validate.fractal_lock import FractalLockResult, fractal_lock
from spine_mj.validate.ground_truth import GroundTruthResult, ground_truth
from spine_mj.validate.plans import ValidationPlan
from spine_mj.validate.quasistatic_limit import QuasistaticLimitResult, quasistatic_limit
from spine_mj.validate.report import array_study as array_study_report
from spine_mj.validate.report import boundary as boundary_report
from spine_mj.validate.report import engines as engines_report
from spine_mj.validate.report import fractal_lock as fractal_lock_report
from spine_mj.validate.report import ground_truth as ground_truth_report
from spine_mj.validate.report import quasistatic_limit as quasistatic_limit_report
from spine_mj.validate.report import sandpaper as sandpaper_report
from spine_mj.validate.report import static_map as static_map_report
from spine_mj.validate.report import stick_slip as stick_slip_report
from spine_mj.validate.report import stiffness_map as stiffness_map_report
from spine_mj.validate.sandpaper import SandpaperResult, sandpaper
from spine_mj.validate.static_map import StaticMapResult, static_map
from spine_mj.validate.stick_slip import StickSlipResult, stick_slip
from spine_mj.validate.stiffness_map import StiffnessMapResult, stiffness_map
from spine_mj.validate.study_runner import StudyRunner

__all__ = ["STUDIES", "Study"]


@dataclass(frozen=True)
class Study:
    """One study of the validation.

    Attributes
    ----------
    name : str
        Its key in ``validation.json``'s ``timings_s`` and in the progress reports.
    run : callable
        ``run(plan, runner) -> result``.
    result : type
        The type of its result.
    report : module
        Its report module: ``section(result, ctx)``, and where the study has any,
        ``headline(result)``, ``summary_lines(validation)``, ``headline_numbers(validation)``
        and ``results_lines(validation)`` (:mod:`spine_mj.validate.report.common`); the
        methods below give none of a kind the module does not state.
    """

    name: str
    run: Callable[[ValidationPlan, StudyRunner], Any]
    result: type
    report: ModuleType

    def _stated(self, name: str, arg: Any, none: Any) -> Any:
        """What the report module's function ``name`` says of ``arg``, or ``none`` where
        the module has no such function (the study has nothing of that kind)."""
        state = getattr(self.report, name, None)
        return state(arg) if state is not None else none

    def headline(self, result: Any) -> list[str]:
        """The study's lines of the report's headline list, from its result."""
        return self._stated("headline", result, [])

    def summary_lines(self, validation: dict) -> list[str]:
        """The study's lines of what ``spine-mj validate`` prints, from its keys of the loaded
        ``validation.json``."""
        return self._stated("summary_lines", validation, [])

    def headline_numbers(self, validation: dict) -> dict:
        """The study's numbers with an interval in the loaded ``validation.json``, by key."""
        return self._stated("headline_numbers", validation, {})

    def results_lines(self, validation: dict) -> list[str]:
        """The study's Markdown block of the site's results page (``docs/tools/generate.py``),
        from its keys of the loaded ``validation.json``."""
        return self._stated("results_lines", validation, [])


#: The studies, in the order they run and appear in the report (the I_e* headline first).
STUDIES: tuple[Study, ...] = (
    Study("boundary", boundary, BoundaryResult, boundary_report),
    Study("limit", quasistatic_limit, QuasistaticLimitResult, quasistatic_limit_report),
    Study("static", static_map, StaticMapResult, static_map_report),
    Study("ground_truth", ground_truth, GroundTruthResult, ground_truth_report),
    Study("stick_slip", stick_slip, StickSlipResult, stick_slip_report),
    Study("sandpaper", sandpaper, SandpaperResult, sandpaper_report),
    Study("fractal_lock", fractal_lock, FractalLockResult, fractal_lock_report),
    Study("stiffness_map", stiffness_map, StiffnessMapResult, stiffness_map_report),
    Study("arrays", array_study, ArrayStudyResult, array_study_report),
    Study("engines", engines_study, EnginesResult, engines_report),
)

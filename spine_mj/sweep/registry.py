"""The analysis registry: what an analysis is, the parameters it reads, what it returns.

An analysis declares its sweepable parameters (:class:`ParamSpec`), the analyses it needs
first and, optionally, a whole-config check; :func:`register_analysis` adds it to
:data:`ANALYSES`, whose order is the run order. The config parser reads the schema of a
sweep from here, so every parameter is declared once, next to the analysis that reads it.
This module imports nothing else from :mod:`spine_mj.sweep`.
"""

from __future__ import annotations

import contextvars
from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import numpy as np
from annotated_types import Interval
from pydantic import AllowInfNan, Strict

from spine_mj.choices import ENGINES, check_engine
from spine_mj.errors import SpineInputError
from spine_mj.theory.engagement import DEFAULT_KAPPA_CAP

#: Threads a case's engine batch may use: 1 where cases run side by side in worker
#: processes or one at a time with ``workers = 1``; the sweep's workers where a single case
#: is left to run (:func:`spine_mj.sweep.executors.run_here`).
#: Read by the analyses that step MuJoCo; a run's result does not depend on it.
CASE_THREADS: contextvars.ContextVar[int] = contextvars.ContextVar("case_threads", default=1)

#: Row statuses. ``ok``; ``failed`` (an exception in the analysis); ``bad_surface`` (the
#: surface could not be made or loaded); MuJoCo trouble by kind: ``nan`` (a non-finite
#: state), ``penetration`` (deeper than the tolerance), ``diverged`` (a speed or position
#: blow-up), ``engine_warning`` (a MuJoCo warning); ``dependency_failed`` (an analysis this
#: one needs did not give a result for the start).
STATUSES = (
    "ok",
    "failed",
    "bad_surface",
    "nan",
    "penetration",
    "diverged",
    "engine_warning",
    "dependency_failed",
)


#: Columns of the run table that every run has; no parameter or metric may take these names.
RESERVED = (
    "run_id",
    "case_id",
    "case_index",
    "analysis",
    "start",
    "start_x",
    "start_y",
    "surface",
    "surface_seed",
    "seed",
    "status",
    "reason",
    "time_s",
    "cpu_s",
)


@dataclass(frozen=True)
class ParamSpec:
    """A sweepable parameter that an analysis reads from ``case.params``.

    Attributes
    ----------
    name : str
    kind : {"float", "int", "str", "bool"}
    doc : str
        One line: meaning and unit.
    default : Any
        Used when the config does not set it; ``REQUIRED`` makes the key mandatory.
    minimum : float, optional
        Lower bound (inclusive unless ``exclusive``).
    exclusive : bool
    maximum : float, optional
        Upper bound (inclusive): where larger values stop making physical sense.
    choices : tuple of str, optional
        Allowed values of a ``str`` parameter.
    drive : bool
        May also be given in the ``[drive]`` table.
    array : bool
        May also be given in the ``[array]`` table (the layout of the ``array`` analysis).
    option : str, optional
        The engine option of :func:`spine_mj.sim.build_rig` it sets (None: not an engine
        option). An engine whose registry entry (:data:`spine_mj.choices.ENGINES`) does not
        list it ignores it: a case of that engine records it as None
        (:func:`applied_params`), a row records only settings that were applied.
    """

    name: str
    kind: str
    doc: str
    default: Any = None
    minimum: float | None = None
    exclusive: bool = False
    choices: tuple[str, ...] | None = None
    drive: bool = False
    maximum: float | None = None
    array: bool = False
    option: str | None = None

    def expected(self) -> str:
        if self.choices:
            return "one of " + ", ".join(repr(c) for c in self.choices)
        what = {"float": "a finite number", "int": "an integer", "str": "a string", "bool": "true or false"}[
            self.kind
        ]
        if self.minimum is not None:
            what += f" {'>' if self.exclusive else '>='} {self.minimum:g}"
        if self.maximum is not None:
            what += f" and <= {self.maximum:g}"
        return what

    @property
    def annotation(self) -> Any:
        """The pydantic type of one value: its kind, bounds and choices (:meth:`expected` in
        words). Integers pass as floats; booleans and strings pass only as themselves."""
        if self.choices:
            return Literal[self.choices]
        kinds = {"float": Annotated[float, AllowInfNan(False)], "int": int, "str": str, "bool": bool}
        low = {"gt" if self.exclusive else "ge": self.minimum}
        return Annotated[kinds[self.kind], Strict(), Interval(**low, le=self.maximum)]


#: ``ParamSpec.default`` of a parameter that every config must set.
REQUIRED = object()

#: ``ParamSpec.default`` of ``mu``: a case that is given none takes its surface's by the
#: rule of every command (:func:`spine_mj.presets.resolve_mu`, through
#: :func:`spine_mj.sweep.config.surface_mu`): its preset's calibrated ``[engagement] mu``; a
#: config must set it when a surface has none (a file, a preset without a calibration).
PRESET_MU = object()

#: The friction coefficient, shared by every analysis that needs one (declared once).
MU_PARAM = ParamSpec(
    "mu",
    "float",
    "static friction coefficient mu_s (default: the preset's calibrated [engagement] mu)",
    PRESET_MU,
    0.0,
    exclusive=True,
)


#: The tip radius, shared by the streamline and the engine so that one config traces one tip
#: in both (declared once; its meaning: :func:`spine_mj.sim.scales.check_tip_radius`).
TIP_RADIUS_PARAM = ParamSpec(
    "tip_radius",
    "float",
    "tip radius in the surface's length unit (default: the rig's default tip, the larger of one "
    "hfield spacing and L_c / 100; 0: a point, which quasistatic traces and an engine refuses)",
    None,
    0.0,
)


#: The force cap, shared by the streamline and the engine so that both call "held" by the
#: same test (declared once; :data:`spine_mj.theory.engagement.DEFAULT_KAPPA_CAP`).
KAPPA_CAP_PARAM = ParamSpec(
    "kappa_cap",
    "float",
    "force cap: a path needing a drive above kappa_cap F_p is held, on the streamline and in MuJoCo alike",
    DEFAULT_KAPPA_CAP,
    0.0,
    exclusive=True,
)


@dataclass(frozen=True, eq=False)
class AnalysisResult:
    """What one analysis gives for one case.

    Attributes
    ----------
    metrics : dict of str to ndarray, each shape (n_starts,)
        Scalars per start (floats, ints or bools); stored as columns of the run table.
    trajectories : dict of str to ndarray, each shape (n_points,), optional
        Long table of paths; must contain ``start`` (int) and ``step`` (int).
    status, reason : ndarray of str, shape (n_starts,), optional
        Per-start status (see :data:`STATUSES`) and reason; None means all ``ok``.
    data : Any
        In-memory result for the analyses that depend on this one (not stored).
    """

    metrics: dict[str, np.ndarray]
    trajectories: dict[str, np.ndarray] | None = None
    status: np.ndarray | None = None
    reason: np.ndarray | None = None
    data: Any = None


@dataclass(frozen=True)
class Analysis:
    """A named analysis: ``func(case, surface, starts, upstream) -> AnalysisResult``.

    ``starts`` is ``(n_starts, 2)`` in the surface's length unit; ``upstream`` maps the
    names in ``requires`` to their results for the same case. ``check_config``, if given,
    is called with every validated config that chooses this analysis and raises
    SpineInputError for a combination of values its parameters cannot check one by one.
    ``check_case``, if given, is ``check_case(case, surface, starts)``: it raises the
    SpineInputError that ``func`` would raise for the case's inputs, without running it
    (:mod:`spine_mj.sweep.preflight` calls it before a sweep starts). ``precheck_case``, if
    given, is the part of it that takes no sizing (the planned hfield's limits): the
    pre-run check runs it on the whole grid first, so a limit one combination breaks is
    refused before seconds of another combination's sizing.

    Attributes
    ----------
    name : str
        The name a config's ``analyses`` list uses.
    func : callable
        ``func(case, surface, starts, upstream) -> AnalysisResult``.
    parameters : tuple of ParamSpec
        The grid keys it reads, with their checks and defaults.
    requires : tuple of str
        Analyses whose results it needs (run first, passed as ``upstream``).
    doc : str
        One line for ``spine-mj sweep --help`` and the report.
    check_config, check_case : callable or None
        See above.
    check_reads : tuple of str, optional
        The parameters ``check_case`` reads (None: every parameter of this analysis and of
        those it requires): the pre-run check calls it once per distinct combination of
        them, so a grid over a parameter the check does not read costs nothing more.
    precheck_case : callable or None
        ``precheck_case(case, surface)``, see above.
    precheck_reads : tuple of str
        The parameters ``precheck_case`` reads (it runs once per distinct combination).
    """

    name: str
    func: Callable[..., AnalysisResult]
    parameters: tuple[ParamSpec, ...]
    requires: tuple[str, ...] = ()
    doc: str = ""
    check_config: Callable[[Any], None] | None = None
    check_case: Callable[..., None] | None = None
    check_reads: tuple[str, ...] | None = None
    precheck_case: Callable[..., None] | None = None
    precheck_reads: tuple[str, ...] = ()


#: Registry of analyses by name; :func:`register_analysis` adds to it.
ANALYSES: dict[str, Analysis] = {}


def register_analysis(analysis: Analysis) -> Analysis:
    """Add ``analysis`` to :data:`ANALYSES` (replacing one of the same name).

    Parameters
    ----------
    analysis : Analysis
        The analysis to register.

    Returns
    -------
    Analysis
        ``analysis``, so that the call can decorate its definition.
    """
    for spec in analysis.parameters:
        if spec.name in RESERVED:
            raise SpineInputError(f"parameter name {spec.name!r} is reserved for the run table")
    ANALYSES[analysis.name] = analysis
    return analysis


def applied_params(params: dict, specs: dict[str, ParamSpec]) -> dict:
    """``params`` with None for every engine option that the case's ``engine`` does not read
    (a :class:`ParamSpec` whose ``option`` its registry entry leaves out)."""
    entry = ENGINES.get(params.get("engine"))
    reads = () if entry is None else entry.options
    return {
        k: None if specs[k].option is not None and specs[k].option not in reads else v
        for k, v in params.items()
    }


def check_engine_options(engine: str, grid: dict, specs) -> None:
    """Refuse an unknown ``engine`` (or its extra missing) and any engine option among
    ``specs`` that ``grid`` sets away from its default and ``engine`` does not read (its
    registry entry's options)."""
    entry = check_engine(engine, "config key engine =")
    given = [
        f"{s.name} = {list(grid[s.name])}"
        for s in specs
        if s.option is not None and s.option not in entry.options and grid[s.name] != (s.default,)
    ]
    if given:
        raise SpineInputError(
            f"config keys {', '.join(given)}: not read by engine {engine} (its options: "
            f"{', '.join(entry.options) or 'none'}); remove them, or sweep that engine separately"
        )


def param_specs(analyses: tuple[str, ...]) -> dict[str, ParamSpec]:
    """The parameters of ``analyses`` by name (the first declaration of a shared name wins)."""
    specs: dict[str, ParamSpec] = {}
    for name in analyses:
        for spec in ANALYSES[name].parameters:
            specs.setdefault(spec.name, spec)
    return specs

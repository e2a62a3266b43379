"""Sizes and targets of a validation run: the plans, their surface families and engine variations.

A :class:`ValidationPlan` fixes what the studies share (families, the lowest I_e, the
analytic surfaces' grid, the bootstrap size) and has one section per study whose sizes are
its own (:mod:`spine_mj.validate.plan_sections`: ``plan.fractal.surfaces``,
``plan.limit.corner``); :data:`PLANS` holds the ``smoke``
(test size), ``quick`` and ``full`` plans. The agreement targets and the physical
constants every study shares (tip mass, gravity, the sandpaper mu) live here, so that the
studies, the summary and the report read one value.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.validate.plan_sections import (
    BoundaryPlan,
    EnginesPlan,
    FractalPlan,
    GroundTruthPlan,
    LimitPlan,
    SandpaperPlan,
    StaticPlan,
    StickSlipPlan,
    StiffnessMapPlan,
)

__all__ = [
    "DT_HALVED",
    "GRAVITY",
    "HFIELD_DOUBLED",
    "HFIELD_QUADRUPLED",
    "IMPRATIO",
    "MASS_KG",
    "MEASURED",
    "NO_NOSLIP",
    "PLANS",
    "RAMP_MIN_COVERAGE",
    "RECOMMENDED",
    "SANDPAPER_MU",
    "STATIC_TARGET",
    "TOLERANCE_TIGHTENED",
    "FamilySpec",
    "ValidationPlan",
    "paper_starts",
    "relative_starts",
]

#: A ramp whose runs cover less of the path to the domain edge gives no I_e*.
RAMP_MIN_COVERAGE = 0.5
STATIC_TARGET = 0.05
MASS_KG = 0.01
GRAVITY = 9.81
SANDPAPER_MU = 0.5


@dataclass(frozen=True)
class FamilySpec:
    """A surface family of the quasistatic-limit and boundary studies.

    Attributes
    ----------
    name : str
        Key in ``validation.json`` (``single_peak_valley``, ``random_gaussian``, ``fractal``).
    presets : tuple of str
    seeds : tuple of int or None
        Surface seeds (None: the preset's own).
    starts : dict
        A sweep ``starts`` table.
    variants : tuple
        Generator parameter sets (a sweep surface's ``set`` table as ``((key, value),
        ...)``), each a surface of every seed; ``((),)``: the preset as it is.
    mu : float or None
        mu_s of the family (None: each preset's calibrated one).
    timestep_factor : float
        The step rule's step times this at the family's quasistatic corner and its
        refinements (the sweep's ``timestep_factor``, the contact's time constant kept): 1
        unless the family's solution verification found the rule's step unconverged, its
        headline moved beyond its interval by ``dt / 2`` but not by the next halving (issue
        41: change the default per family where it does not converge). Then the coarsest
        factor whose halving stays inside, and the refinements are relative to it.
    """

    name: str
    presets: tuple[str, ...]
    seeds: tuple[int, ...] | None
    starts: tuple[tuple[str, Any], ...]
    variants: tuple[tuple[tuple[str, Any], ...], ...] = ((),)
    mu: float | None = None
    timestep_factor: float = 1.0

    def __post_init__(self):
        if not (math.isfinite(self.timestep_factor) and 0 < self.timestep_factor <= 1):
            raise SpineInputError(
                f"FamilySpec {self.name!r}: timestep_factor must be in (0, 1], got {self.timestep_factor!r}"
            )

    def starts_table(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.starts}

    def first_start(self, surface) -> tuple[float, float]:
        """The first start in ``surface`` units (a relative frame scaled to its bounds)."""
        t = self.starts_table()
        x, y = float(t["x"][0]), float(t["y"][0])
        if t.get("frame") == "relative":
            xmin, xmax, ymin, ymax = surface.bounds
            x, y = xmin + x * (xmax - xmin), ymin + y * (ymax - ymin)
        return x, y


def paper_starts(ys: Sequence[float]) -> tuple:
    """Starts at x = -3 and the given ``ys`` in surface units (the paper's single peak/valley)."""
    return (("frame", "absolute"), ("x", (-3.0,)), ("y", tuple(float(y) for y in ys)))


def relative_starts(n: int, x: float = 0.05) -> tuple:
    """``n`` starts at relative ``x``, spread over y in [0.2, 0.8] of the domain."""
    return (("frame", "relative"), ("x", (x,)), ("y", tuple(np.linspace(0.2, 0.8, n).round(4))))


@dataclass(frozen=True)
class ValidationPlan:
    """Sizes of a validation run.

    Attributes
    ----------
    name : str
    families : tuple of FamilySpec
        Quasistatic-limit families.
    lowest_ie : float
    hfield_resolution : int
        Samples per side of analytic surfaces (grid surfaces keep their own).
    static : StaticPlan
        The static map's planes and engine settings (:mod:`spine_mj.validate.static_map`).
    boundary : BoundaryPlan
        The boundary study's grid, drives and ramp (:mod:`spine_mj.validate.boundary`).
    bootstrap : int
        Bootstrap resamples of the starts for the I_e* uncertainty.
    limit : LimitPlan
        The quasistatic-limit study's sizes: its corner's starts, ensembles, refinements
        and engine variations (:mod:`spine_mj.validate.quasistatic_limit`).
    stick_slip : StickSlipPlan
        The stick-slip study's sizes (:mod:`spine_mj.validate.stick_slip`).
    sandpaper : SandpaperPlan
        The sandpaper study's sizes (:mod:`spine_mj.validate.sandpaper`).
    fractal : FractalPlan
        The fractal self-lock study's sizes (:mod:`spine_mj.validate.fractal_lock`).
    stiffness_map : StiffnessMapPlan
        The (I_e, K) map's sizes (:mod:`spine_mj.validate.stiffness_map`).
    ground_truth : GroundTruthPlan
        The ground-truth study's sizes (:mod:`spine_mj.validate.ground_truth`).
    engines : EnginesPlan
        The engines study's checks (:mod:`spine_mj.validate.engines`).
    """

    name: str
    families: tuple[FamilySpec, ...]
    lowest_ie: float
    hfield_resolution: int
    static: StaticPlan
    boundary: BoundaryPlan
    bootstrap: int = 200
    limit: LimitPlan = field(default_factory=LimitPlan)
    stick_slip: StickSlipPlan = field(default_factory=StickSlipPlan)
    sandpaper: SandpaperPlan = field(default_factory=SandpaperPlan)
    fractal: FractalPlan = field(default_factory=FractalPlan)
    stiffness_map: StiffnessMapPlan = field(default_factory=StiffnessMapPlan)
    ground_truth: GroundTruthPlan = field(default_factory=GroundTruthPlan)
    engines: EnginesPlan = field(default_factory=EnginesPlan)
    extra: dict = field(default_factory=dict, compare=False)


#: Engine variations: (label, sweep grid overrides); the first is the rig's default.
RECOMMENDED = ("recommended (elliptic, noslip 3)", ())
NO_NOSLIP = ("no noslip (elliptic, impratio 1)", (("noslip_iterations", 0),))
IMPRATIO = ("no noslip, impratio 10", (("noslip_iterations", 0), ("impratio", 10.0)))
#: The rig's step halved, the contact's time constant kept (solution verification).
DT_HALVED = ("time step / 2 (contact solref kept)", (("timestep_factor", 0.5),))
#: The surface's grid at twice the samples a side (solution verification of the static map).
HFIELD_DOUBLED = ("hfield x 2", (("hfield_factor", 2),))
#: ... and at four times (the static map's third level: a plane's last change x 2 -> x 4).
HFIELD_QUADRUPLED = ("hfield x 4", (("hfield_factor", 4),))
#: MuJoCo's solver tolerances a hundredth of their defaults (solution verification).
TOLERANCE_TIGHTENED = ("tolerance / 100", (("tolerance", 1e-10), ("noslip_tolerance", 1e-8)))

#: The paper's single peak and valley with the five starts of Figs. 3-4 (every plan).
#: The fractal family: 3 seeds x 2 Hurst exponents x 5 starts.
FRACTAL = FamilySpec(
    "fractal",
    ("paper-fractal",),
    (1, 2, 3),
    relative_starts(5),
    variants=((("hurst", 0.7),), (("hurst", 0.9),)),
)

#: The three sandpaper grits with their 25 um tip. Starts a quarter in: the rig ends a run
#: whose tip comes within a tip radius of the edge, and the P600 patch is 16 radii wide.
SANDPAPER = FamilySpec(
    "sandpaper",
    ("sandpaper-P36", "sandpaper-P60", "sandpaper-P600"),
    None,
    relative_starts(3, 0.25),
    mu=SANDPAPER_MU,
)

#: The two instrument scans that ship with spine_mj (``example:NAME``, spine_mj.examples):
#: a 576 x 768 profilometer scan (plu-1, 1.27 x 0.95 mm, L_c 32 um) and a 512 x 512 AFM
#: scan (di-1, 0.5 um a side, L_c 0.12 um). Starts half-way in along x: the plu scan is 40
#: L_c long, and a path across half of it is already 20 L_c. Their roughness has no
#: calibrated mu_s: the sandpaper's.
MEASURED = FamilySpec(
    "measured",
    ("example:plu-1.plu", "example:di-1.di"),
    None,
    relative_starts(3, 0.5),
    mu=SANDPAPER_MU,
)

#: At half the rule's step: at the rule's own, the median Frechet distance is 0.013 L_c above
#: its dt / 2 value, beyond its interval and the metric's resolution, and dt / 4 moves it a
#: further 0.002 (full plan at 84faaed, 30 paired starts). The cause is MuJoCo's, not the
#: surface's: a tip sliding on the soft contact hops (airborne 65-75 % of the steps even on a
#: flat plane, at every step, contact time constant, noslip and impratio tried), and the hops'
#: lateral drift is first order in the step (the single peak's 15 starts: 0.021, 0.011,
#: 0.0068, 0.0056 L_c at dt, dt / 2, dt / 4, dt / 8; docs/physics.md §5).
PEAK_VALLEY = FamilySpec(
    "single_peak_valley",
    ("paper-single-peak", "paper-single-valley"),
    None,
    paper_starts([-0.5, -1.0, -2.0, -3.0, -4.0]),
    timestep_factor=0.5,
)

PLANS: dict[str, ValidationPlan] = {
    "smoke": ValidationPlan(
        name="smoke",
        families=(
            FamilySpec("single_peak_valley", ("paper-single-peak",), None, paper_starts([-2.0, -4.0])),
        ),
        lowest_ie=1e-2,
        hfield_resolution=101,
        bootstrap=20,
        limit=LimitPlan(
            convergence_starts=1,
        ),
        stick_slip=StickSlipPlan(
            ie=(1e-1,),
            stiffness=(10.0,),
            starts=1,
            k_ie=(1e-2,),
            k_factors=(0.25, 4.0),
        ),
        sandpaper=SandpaperPlan(
            grits=(),
        ),
        fractal=FractalPlan(
            hursts=(0.65, 0.95),
            surfaces=1,
            facets=False,
            refinements=("dt_halved",),
            refined_surfaces=1,
        ),
        stiffness_map=StiffnessMapPlan(
            ie=(1e-1, 1.0),
            k=(30.0,),
            families=("single_peak_valley",),
            starts=1,
        ),
        ground_truth=GroundTruthPlan(
            slopes=(0.3,),
            mus=(0.5,),
            k_factors=(0.25, 4.0),
            waves=3,
            ridge_widths=(0.5,),
            liftoff_factors=(0.5, 1.5),
        ),
        engines=EnginesPlan(
            # the engines study's two cheapest checks: 2.6 s of CPU in both engines
            checks=("static kappa", "spring-block"),
            quick=True,
        ),
        static=StaticPlan(
            slopes_deg=(20.0, 70.0),
            azimuths_deg=(0.0,),
            engines=(RECOMMENDED, DT_HALVED, HFIELD_DOUBLED),
        ),
        boundary=BoundaryPlan(
            ie_values=(1e-2, 1.0),
            families=("single_peak_valley",),
            protocols=("spring",),
            ramp_max_steps=2000,
            refinements=("dt_halved",),
        ),
    ),
    "quick": ValidationPlan(
        name="quick",
        families=(
            PEAK_VALLEY,
            FamilySpec(
                "random_gaussian", ("paper-random-convex", "paper-random-concave"), (1,), relative_starts(3)
            ),
            FRACTAL,
            SANDPAPER,
            MEASURED,
        ),
        lowest_ie=1e-4,
        hfield_resolution=151,
        bootstrap=200,
        limit=LimitPlan(
            # the engine settings' variations are the full plan's (the demo's budget)
            variations=(),
            # two runs a start (the full plan's three: the start and its neighbours on either
            # side along x): a split is looked for on one side only, so the demo's
            # ill-conditioned shares are lower bounds beside the full plan's. The ensembles'
            # third runs were a third of the demo's MuJoCo time (43 of 130 s of CPU, measured)
            ensemble_members=2,
            # at least 36 starts per family (issue 41: 30 well-conditioned at least): 35 agreeing
            # ones are the fewest whose Wilson interval can meet the 95 % target
            # (intervals.runs_to_meet), one more leaves room for a start found ill-conditioned;
            # the fractal, with one start in eight ill-conditioned (full report), 42
            corner=(
                ("single_peak_valley", None, paper_starts(np.linspace(-0.5, -4.0, 18).round(4))),
                ("random_gaussian", (1,), relative_starts(18)),
                ("fractal", (1, 2, 3), relative_starts(7)),
                ("sandpaper", None, relative_starts(12, 0.25)),
                ("measured", None, relative_starts(18, 0.5)),
            ),
            # solution verification on 6 paired starts a family (the demo's budget; the full
            # plan's 30 give the verdicts)
            convergence_starts=6,
            # the compliant reference creeps along the creases of the scan di-1 and the grits'
            # facets: 6 di-1 starts took 72.8 CPU-s with it and 16.7 without (the full plan has it)
            compliant_reference=False,
        ),
        stick_slip=StickSlipPlan(
            ie=(1e-2, 1.0),
            stiffness=(2.0, 50.0),
            starts=2,
            k_ie=(1e-4,),
            k_factors=(0.25, 0.5, 1.0, 2.0, 4.0),
        ),
        sandpaper=SandpaperPlan(
            grits=("P36", "P600"),
            starts=2,
        ),
        fractal=FractalPlan(
            surfaces=6,
            # the facet streamline (~1.4 s per surface, measured) would double the study's time
            facets=False,
        ),
        stiffness_map=StiffnessMapPlan(
            # I_e low enough that the stiffer K are read where their spring-block swing is
            # small (theory_orders.k_readings), one deeper at the stiffest (10 K*)
            ie=(1e-3, 1e-1),
            # a reduced ladder around each family's K_path, with its fold K* and 10 K*
            k_factors=(0.3, 1.0, 3.0),
            deep_ie=(1e-4,),
            families=("single_peak_valley", "random_gaussian", "fractal"),
            starts=2,
        ),
        ground_truth=GroundTruthPlan(
            k_factors=(0.25, 4.0),
            waves=4,
            ridge_widths=(0.35, 0.5),
            liftoff_factors=(0.5, 0.8, 1.1, 1.5),
        ),
        engines=EnginesPlan(
            # every engines check, Prandtl-Tomlinson over 2 wavelengths: 33 s of process CPU
            # (MuJoCo 3.3 s, Bullet 23.3 s, imports the rest; measured on a loaded machine)
            quick=True,
        ),
        static=StaticPlan(
            slopes_deg=(0.0, 15.0, 30.0, 45.0, 60.0, 75.0),
            azimuths_deg=(0.0, 60.0, 120.0, 180.0),
            engines=(RECOMMENDED, NO_NOSLIP, DT_HALVED),
        ),
        boundary=BoundaryPlan(
            # the boundary lies at 1e-2 to 1 on the single peak and valley: 1e-4 (the corner
            # study's I_e) brackets nothing there and its ramp pilot was the boundary's slowest
            ie_values=(1e-3, 1e-2, 1e-1, 1.0, 10.0),
            families=("single_peak_valley",),
            # the spring drive's boundary only: the ramp's pilots run one by one (78 of the
            # boundary's 113 s measured), and the full plan has both drives
            protocols=("spring",),
            ramp_max_steps=60000,
        ),
    ),
    "full": ValidationPlan(
        name="full",
        families=(
            PEAK_VALLEY,
            FamilySpec(
                "random_gaussian",
                ("paper-random-convex", "paper-random-concave"),
                (1, 2),
                relative_starts(5),
            ),
            FRACTAL,
            SANDPAPER,
            MEASURED,
        ),
        lowest_ie=1e-4,
        hfield_resolution=201,
        bootstrap=500,
        limit=LimitPlan(
            variations=(
                NO_NOSLIP,
                IMPRATIO,
                ("no noslip, impratio 100", (("noslip_iterations", 0), ("impratio", 100.0))),
                ("hfield 101", (("hfield_resolution", 101),)),
                # hfield 401 and timestep / 2 are the corner's own refinements (hfield_doubled,
                # dt_halved: the same settings on every family), not repeated here
                ("soft contact (timeconst 10 dt)", (("solref_timeconst_factor", 10.0),)),
            ),
            ensemble_members=3,
            # at least 60 well-conditioned starts per family (issue 41: 60 of 60 has a 95 % lower
            # bound of 0.94), over several surfaces: 64 where one start in a hundred was
            # ill-conditioned (the paper families), 80 on the fractal (5 seeds x 2 H; one in
            # eight), 78 on the sandpaper (one in nine ill-conditioned or stopped), 68 on the scans
            corner=(
                # y = -5 was the domain's edge, where a run ends at once (now refused)
                ("single_peak_valley", None, paper_starts(np.linspace(-0.25, -4.75, 32).round(4))),
                ("random_gaussian", (1, 2), relative_starts(16)),
                ("fractal", (1, 2, 3, 4, 5), relative_starts(8)),
                ("sandpaper", None, relative_starts(26, 0.25)),
                ("measured", None, relative_starts(34, 0.5)),
            ),
            # solution verification on at least 30 well-conditioned paired starts a family, three
            # step levels and (on the gridded surfaces) three hfield levels for observed orders and
            # GCIs: 36 paired, since one start in nine is ill-conditioned on the grits (27 of 30
            # well-conditioned at 021006f) and 29 of 30 on the scans at hfield x 2
            convergence_starts=36,
            # ... and on every start where the refined runs are cheap (the fractal's dt / 4
            # took 41 CPU-s for 30 runs; a grit's 168)
            convergence_all_starts=("single_peak_valley", "random_gaussian", "fractal"),
            convergence_refinements=(
                "dt_halved",
                "dt_quartered",
                "hfield_doubled",
                "hfield_quadrupled",
                "tolerance_tightened",
            ),
            # the compliant reference is the corner's costliest part on the grits and scans
            # (it creeps along their creases: 34 of a P600 case's 51.5 CPU-s); at a corner
            # whose K is well above the family's K_path the spring's compliance is what the
            # corner rule removes, and the (I_e, K) map keeps the compliant I_e*
            compliant_reference=False,
        ),
        stick_slip=StickSlipPlan(
            ie=(1e-3, 1e-2, 1e-1, 1.0),
            stiffness=(2.0, 10.0, 50.0),
            starts=3,
        ),
        sandpaper=SandpaperPlan(
            starts=4,
        ),
        stiffness_map=StiffnessMapPlan(
            ie=(1e-4, 1e-3, 1e-2, 1e-1, 1.0),
            # K / K* to 10 on every family, by factors of at most 2 around K* (the predicted K*
            # is judged within a factor of 2); I_e down to 1e-6 at the stiffest K, on the fractal
            # at every K (deep_every_k). Measured on the fractal at K = 1000, one
            # start, busy machine: 3.0 s at I_e 1e-4, 47 s at 1e-5 (its stick phases too short
            # for the fast-forward), 1.6 s at 1e-6 (fast-forwarded; 36 s without): the ladder
            # skips 1e-5
            # K / K_path by factors of at most 2 around K_path (judged within a factor of 2),
            # with each family's fold K* and 10 K* (family_k_axis)
            k_factors=(0.1, 0.3, 0.5, 1.0, 2.0, 3.0),
            deep_ie=(1e-6,),
            deep_starts=10,
            deep_every_k=("fractal",),
            families=("single_peak_valley", "random_gaussian", "fractal"),
            # at least 30 runs per (I_e, K) point and family (StiffnessMapPlan.map_family)
            starts=30,
            runs=30,
        ),
        fractal=FractalPlan(
            # both MuJoCo series on 15 of the 30 surfaces per H: ~0.53 s a surface with dt / 2,
            # ~0.35 s with the tolerances / 100 (measured, busy machine): ~67 s of CPU; dt / 4
            # (an observed order) would add ~80 s
            refinements=("dt_halved", "tolerance_tightened"),
            refined_surfaces=15,
        ),
        static=StaticPlan(
            slopes_deg=tuple(np.arange(0.0, 76.0, 7.5)),
            azimuths_deg=(0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0),
            engines=(
                RECOMMENDED,
                NO_NOSLIP,
                IMPRATIO,
                DT_HALVED,
                HFIELD_DOUBLED,
                HFIELD_QUADRUPLED,
                TOLERANCE_TIGHTENED,
            ),
        ),
        boundary=BoundaryPlan(
            ie_values=tuple(float(v) for v in np.logspace(-4, 1, 11)),
            # the random Gaussian boundary (20 runs x 11 I_e x 2 drives) would double the run
            # time past ~45 min on 2 cores: the full plan keeps the single peak/valley there
            families=("single_peak_valley",),
            ramp_max_steps=200_000,
            # I_e* rerun around its bracket (4 I_e x 10 starts x 2 drives a refinement): ~155 s
            # of CPU for both, estimated from a reduced run (spring 0.45-0.5 s a run, ramp 1.1-1.8
            # s); dt / 4 for an observed order would add ~170 s
            refinements=("dt_halved", "hfield_doubled"),
        ),
    ),
}

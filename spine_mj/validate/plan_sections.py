"""The sections of a validation plan (:class:`spine_mj.validate.plans.ValidationPlan`): one
frozen record per study whose sizes are its own (``plan.fractal.surfaces``), so that a
study reads its section and a new study adds one section.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = [
    "BoundaryPlan",
    "EnginesPlan",
    "FractalPlan",
    "GroundTruthPlan",
    "LimitPlan",
    "SandpaperPlan",
    "StaticPlan",
    "StickSlipPlan",
    "StiffnessMapPlan",
]


@dataclass(frozen=True)
class StickSlipPlan:
    """The stick-slip study's sizes (:mod:`spine_mj.validate.stick_slip`).

    Attributes
    ----------
    ie : tuple of float
    stiffness : tuple of float
        Spring stiffness in units of ``F_p / L_c``.
    starts : int
    k_ie, k_factors : tuple of float
        The stick-slip study's K scan on a corrugation: I_e values and K in units of K*.
    """

    ie: tuple[float, ...] = (1e-3, 1e-1, 1.0)
    stiffness: tuple[float, ...] = (2.0, 10.0, 50.0)
    starts: int = 3
    k_ie: tuple[float, ...] = (1e-4, 1e-2)
    k_factors: tuple[float, ...] = (0.125, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 4.0, 8.0)


@dataclass(frozen=True)
class LimitPlan:
    """The quasistatic-limit study's sizes (:mod:`spine_mj.validate.quasistatic_limit`).

    Attributes
    ----------
    variations : tuple of (label, ((key, value), ...))
        Engine settings (sweep grid keys) varied one at a time on the first family's first
        preset at its corner; empty: none.
    ensemble_members : int
        Runs per start, on each side: the start and ``ensemble_members - 1`` starts around
        it (:mod:`spine_mj.validate.ensembles`); 1: no ensembles (no start is found
        ill-conditioned).
    corner : tuple of (family name, seeds, starts)
        The study's own seeds and starts table per family (the corner's sample size), where
        they differ from the family's (which the boundary study and the (I_e, K) map draw
        on); :meth:`corner_family`.
    convergence_starts : int
        Paired starts per corner family rerun under refinement, at least (solution
        verification, :mod:`spine_mj.validate.convergence`: the same number of y starts on
        each of its surfaces; 0: none).
    convergence_all_starts : tuple of str
        Families whose refinements rerun every start of their corner, not
        ``convergence_starts`` of them: where a rate's changes come in flips of one run, a
        flip on 30 paired starts is 0.033, coarser than the headline's interval on 60-80
        starts can take twice (the fractal: 2 of 28 flipped under dt / 4, +0.071 against
        an interval of [0.83, 0.96]); on every start the change is the headline's own, like
        for like. For the families whose refined runs are cheap.
    convergence_refinements : tuple of str
        The refinements (keys of :data:`spine_mj.validate.convergence.REFINEMENTS`); with
        ``dt_quartered`` beside ``dt_halved`` three step levels give an observed order.
    compliant_reference : bool
        Whether the corner's runs are also compared with the compliant-drive streamline of
        their own spring (the sweep's ``compare`` key; the refinement levels and engine
        variations never are: they are judged on the rigid reference alone).
    """

    variations: tuple[tuple[str, tuple[tuple[str, Any], ...]], ...] = ()
    ensemble_members: int = 1
    corner: tuple[tuple[str, Any, tuple], ...] = ()
    convergence_starts: int = 0
    convergence_all_starts: tuple[str, ...] = ()
    convergence_refinements: tuple[str, ...] = ("dt_halved", "hfield_doubled")
    compliant_reference: bool = True

    def corner_family(self, fam):
        """``fam`` (a :class:`~spine_mj.validate.plans.FamilySpec`) with the seeds and starts
        of its corner (``corner``; as it is where ``corner`` has no entry for it)."""
        for name, seeds, starts in self.corner:
            if name == fam.name:
                return dataclasses.replace(fam, seeds=seeds, starts=starts)
        return fam


@dataclass(frozen=True)
class SandpaperPlan:
    """The sandpaper study's sizes (:mod:`spine_mj.validate.sandpaper`).

    Attributes
    ----------
    grits : tuple of str
    starts : int
    ie : float
    """

    grits: tuple[str, ...] = ("P36", "P60", "P600")
    starts: int = 3
    ie: float = 1e-3


@dataclass(frozen=True)
class FractalPlan:
    """The fractal self-lock study's sizes (:mod:`spine_mj.validate.fractal_lock`).

    Attributes
    ----------
    hursts : tuple of float
        Hurst exponents of the fractal self-lock study (Figs. 7E and 9 in dynamics); the
        default five lie in the preset's Fig. 9 list, so their surfaces are a Fig. 9 run's.
    surfaces : int
        Fractal surfaces per H (one start each): enough for a rate with a usable binomial
        interval in the full plan (>= 30), fewer in the quick one.
    dynamic_ie : float
        The I_e of the study's dynamic MuJoCo series (its other one runs at ``lowest_ie``).
    refinements : tuple of str
        Refinements of the fractal self-lock rates (keys of
        :data:`spine_mj.validate.convergence.REFINEMENTS`; empty: none): both MuJoCo series
        rerun on the first ``refined_surfaces`` surfaces of each H
        (:mod:`spine_mj.validate.fractal_lock`).
    refined_surfaces : int
    facets : bool
        Also count the streamline traced on MuJoCo's facets (the ``compare`` analysis's
        reference, ~1.4 s of CPU per surface measured on the fractal preset, twice the
        MuJoCo runs' cost there).
    """

    hursts: tuple[float, ...] = (0.65, 0.75, 0.8, 0.85, 0.95)
    surfaces: int = 30
    dynamic_ie: float = 0.1
    facets: bool = True
    refinements: tuple[str, ...] = ()
    refined_surfaces: int = 0


@dataclass(frozen=True)
class StiffnessMapPlan:
    """The (I_e, K) map's sizes (:mod:`spine_mj.validate.stiffness_map`).

    Attributes
    ----------
    ie, k : tuple of float
        Grid of the (I_e, K) map of the spring drive, K = k l_s / F_p (empty: no map).
    k_factors : tuple of float
        The map's K axis relative to each family's predicted K*
        (:mod:`spine_mj.validate.predicted_limits`): K = factor x K*, two digits (empty: the
        absolute ``k`` on every family).
    deep_ie : tuple of float
        I_e values below the map's grid, run at each family's stiffest K only: the gap to
        the streamline against I_e where the spring's offset is smallest (the convergence
        to the theory, :mod:`spine_mj.validate.theory_orders`).
    deep_starts : int
        Starts per preset of those deep runs (0: the map's): a run at I_e = 1e-6 is slow
        (a carriage 100 times slower than at 1e-2).
    deep_every_k : tuple of str
        Families (by name) whose deep I_e runs at every K of their axis, not the stiffest
        only: where every K fails at the grid's lowest I_e the K boundary can be read on
        the deep cells alone (the fractal: every K fails at 1e-4, 10 K* included; a deep
        fractal run costs 0.5 to 1.4 s of CPU, a single peak/valley or random Gaussian one
        3 to 7 s).
    families : tuple of str
        Families (by name) of the map.
    starts : int
        Starts per preset of the map (a subset of the family's): the lowest I_e and the
        many K values make the map's expensive corner, so it runs from few starts.
    runs : int
        Runs per (I_e, K) point and family the map needs at least (0: the family's own
        starts, ``starts`` of them; :meth:`map_family`).
    """

    ie: tuple[float, ...] = ()
    k: tuple[float, ...] = ()
    families: tuple[str, ...] = ()
    k_factors: tuple[float, ...] = ()
    deep_ie: tuple[float, ...] = ()
    deep_starts: int = 0
    deep_every_k: tuple[str, ...] = ()
    starts: int = 2
    runs: int = 0

    def deep_k_axis(self, family: str, ks: Sequence[float]) -> list[float]:
        """The K values of ``family``'s deep I_e runs (``deep_ie``): its whole
        axis ``ks`` where ``deep_every_k`` names it, else its stiffest K."""
        return sorted(ks) if family in self.deep_every_k else [max(ks)]

    def map_family(self, fam):
        """``fam`` (a :class:`~spine_mj.validate.plans.FamilySpec`) for the (I_e, K) map: with
        ``runs`` > 0, its y starts
        respread over the same range, as many as that many runs per (I_e, K) point need on
        the map's one surface per preset (``starts``, at least as many, then
        keeps them all)."""
        if self.runs <= 0:
            return fam
        t = dict(fam.starts)
        ys = [float(v) for v in t["y"]]
        n = -(-self.runs // len(fam.presets))
        t["y"] = tuple(float(v) for v in np.linspace(min(ys), max(ys), n).round(4))
        return dataclasses.replace(fam, starts=tuple(t.items()))


@dataclass(frozen=True)
class GroundTruthPlan:
    """The ground-truth study's sizes (:mod:`spine_mj.validate.ground_truth`).

    Attributes
    ----------
    slopes, mus : tuple of float
        Corrugations of the ground-truth study's Prandtl-Tomlinson check (slope amplitude
        x mu, each slope below each mu).
    k_factors : tuple of float
        Stiffness numbers of that check in units of each corrugation's K*.
    waves : int
        Wavelengths of those corrugations.
    ridge_widths : tuple of float
        Gaussian ridge widths (height 0.5) of the lift-off check.
    liftoff_factors : tuple of float
        I_e of the lift-off scans in units of each ridge's predicted I_e*.
    """

    slopes: tuple[float, ...] = (0.1, 0.2, 0.3)
    mus: tuple[float, ...] = (0.5, 0.8)
    k_factors: tuple[float, ...] = (0.25, 0.5, 2.0, 4.0)
    waves: int = 6
    ridge_widths: tuple[float, ...] = (0.35, 0.5, 0.7)
    liftoff_factors: tuple[float, ...] = (0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.2, 1.5)


@dataclass(frozen=True)
class EnginesPlan:
    """The engines study's checks (:mod:`spine_mj.validate.engines`).

    Attributes
    ----------
    checks : tuple of str or None
        The checks of the engines study (names of :data:`spine_mj.validate.engines.CHECKS`;
        None: all), run in MuJoCo and Bullet where the ``[bullet]`` extra is installed.
    quick : bool
        The engines study's Prandtl-Tomlinson over fewer wavelengths (2, not 3).
    """

    checks: tuple[str, ...] | None = None
    quick: bool = False


@dataclass(frozen=True)
class StaticPlan:
    """The static map's planes and engine settings (:mod:`spine_mj.validate.static_map`).

    Attributes
    ----------
    slopes_deg, azimuths_deg : tuple of float
        Inclined planes of the static map (azimuth 0: rising in the drive direction +x).
    engines : tuple of (label, ((key, value), ...))
        Engine settings of the static map as sweep grid keys; the first is the default.
    """

    slopes_deg: tuple[float, ...]
    azimuths_deg: tuple[float, ...]
    engines: tuple[tuple[str, tuple[tuple[str, Any], ...]], ...]


@dataclass(frozen=True)
class BoundaryPlan:
    """The boundary study's grid, drives and ramp (:mod:`spine_mj.validate.boundary`).

    Attributes
    ----------
    ie_values : tuple of float
        Boundary study grid.
    families : tuple of str
        Families (by name) of the boundary study.
    protocols : tuple of str
    ramp_max_steps : int
        Time cap of a ramp-with-reset run in engine steps (after the settle phase). The
        ramp's duration is the time its measured per-cycle slip needs to cover the path to
        the domain edge, capped here (see :func:`ramp_duration`).
    ramp_slide_lc : float
        Distance the tip slides after each breakaway before the force resets, in ``L_c``
        (the step of the paper's algorithm). The paper's dl = 0.01 sigma would need ~500
        cycles per path here; 0.1 L_c keeps a run affordable and is compared with the
        streamline stepped at its own, converged dl.
    refinements : tuple of str
        The refinements of the boundary study's I_e* (keys of
        :data:`spine_mj.validate.convergence.REFINEMENTS`; empty: none): every start rerun
        at the I_e values around the headline's bracket (:mod:`spine_mj.validate.boundary`).
    """

    ie_values: tuple[float, ...]
    families: tuple[str, ...]
    protocols: tuple[str, ...] = ("spring", "ramp")
    ramp_max_steps: int = 20000
    ramp_slide_lc: float = 0.1
    refinements: tuple[str, ...] = ()

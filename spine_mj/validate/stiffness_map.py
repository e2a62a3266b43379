"""Study 7: the quasistatic boundary as a map over (I_e, K) for the spring drive.

A spring drive is quasistatic only when it is slow (I_e << 1) *and* stiff: a spring of
stiffness ``k`` holding ``F`` stores ``F^2 / (2 k)``, released into the tip at every
breakaway whatever the carriage speed (:mod:`spine_mj.theory.energy`). The drive stiffness number
``K = k l_s / F_p`` (``l_s``: the slope correlation length) measures that release against
the work over one slope length. This study runs the spring drive on a grid of I_e x K for
the plan's families and reports, from the same runs:

- agreement per (family, K, I_e) by the boundary study's criterion (outcome agreement
  >= 95 % and median Frechet <= 0.1 L_c) and I_e*(K) per family with its bracket and
  bootstrap interval over starts (:func:`spine_mj.validate.ie_star.ie_star_by_criterion`);
- per K, the spring energy released at breakaways against the quasistatic work of the
  streamline (``F_p integral kappa dx``), both per L_c travelled;
- slip events (:func:`spine_mj.validate.stick_slip.slip_statistics`): their sizes and force
  drops, how often and how long the tip slips, and how many quasistatic traps MuJoCo skips;
- the same agreement against the compliant-drive streamline of each run's spring
  (``agreement_compliant``: what the spring does predicted, inertia left over), and the
  drive limits predicted from each family's geometry (``predicted``,
  :mod:`spine_mj.validate.predicted_limits`) beside the measured boundary.

Each preset runs from few starts (``plan.stiffness_map.starts``): the lowest I_e and the
many K values make the expensive corner (drive cost grows as I_e^-1/2).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import pandas as pd

from spine_mj import presets, sim, sweep
from spine_mj.errors import SpineInputError
from spine_mj.theory.energy import elastic_release_j, quasistatic_work_j
from spine_mj.theory.motion import SLIPPING
from spine_mj.validate.boundary import preset_grid, quasistatic_locked
from spine_mj.validate.convergence import thin_starts
from spine_mj.validate.ie_star import ie_star_by_criterion, passes_criterion, quiet_nan_warnings
from spine_mj.validate.paths import mujoco_traces
from spine_mj.validate.plans import GRAVITY, MASS_KG, FamilySpec, ValidationPlan
from spine_mj.validate.predicted_limits import families_limits, family_k_axis
from spine_mj.validate.slip_tails import fit_tail
from spine_mj.validate.stick_slip import slip_statistics
from spine_mj.validate.study_runner import StudyRunner
from spine_mj.validate.sweep_configs import family_doc
from spine_mj.validate.theory_orders import order_rows, prediction_check

__all__ = [
    "SLIP_FAMILIES",
    "StiffnessMapResult",
    "agreement_map",
    "energy_rows",
    "slip_rows",
    "stiffness_map",
    "subset_starts",
]

#: Families whose slip events the study collects (rough enough to stick and slip).
SLIP_FAMILIES = ("random_gaussian", "fractal")


#: The agreement criterion of the map: the boundary study's headline one.
CRITERION = "median_frechet"


@dataclass(frozen=True)
class StiffnessMapResult:
    """Result of :func:`stiffness_map`.

    Attributes
    ----------
    ie, stiffness_numbers : list of float
        The grid: I_e values (the deep ones of the stiffest K included) and every K = k l_s /
        F_p value of any family.
    families : list of str
    starts_per_preset : int
    agreement : dict
        family -> K (str) -> per-I_e lists (see :func:`agreement_map`): ``ie``,
        ``agreement``, ``median_frechet``, ``passes``, ``n_ok``, ``n``, and ``ie_star``, the
        I_e* of the criterion (:meth:`IeStar.as_dict` plus ``criterion``).
    energy : list of dict
        Per K at the lowest I_e (:func:`energy_rows`).
    slip : list of dict
        Per (I_e, K) over :data:`SLIP_FAMILIES` (:func:`slip_rows`).
    slip_samples : dict
        ``(ie, K)`` -> ``{"jump_lc": ndarray, "force_drop_fp": ndarray}``: every slip event
        of the :data:`SLIP_FAMILIES` runs without engine trouble, for the CCDF figure (not
        in ``validation.json``).
    tails : list of dict
        Per (I_e, K) and quantity (``jump_lc``, ``force_drop_fp``): the maximum-likelihood
        tail fit (:func:`spine_mj.validate.slip_tails.fit_tail`; series of fewer than 200
        events are counted, not fitted).
    k_by_family : dict
        Family -> its K axis (:func:`family_k_axis`: ``k_factors`` x its predicted K_path
        with its fold K* and 10 K*, or the plan's K values).
    k_factors : list of float
        The ladder K / K* (empty: absolute K values).
    orders : list of dict
        The gap to the streamline against I_e and 1/K per family with its fitted and
        predicted order (:func:`spine_mj.validate.theory_orders.order_rows`).
    prediction_check : list of dict
        The predicted K* and I_e* against the measured ones per family
        (:func:`spine_mj.validate.theory_orders.prediction_check`).
    transitions : list of dict
        Per I_e: the K bracket where stick-slip (at least :data:`SLIPS_PER_LC` slip events
        per L_c) gives way to steady sliding on the :data:`SLIP_FAMILIES` runs.
    """

    ie: list[float]
    stiffness_numbers: list[float]
    families: list[str]
    starts_per_preset: int
    agreement: dict
    energy: list[dict]
    slip: list[dict]
    slip_samples: dict = dataclasses.field(default_factory=dict, compare=False)
    tails: list = dataclasses.field(default_factory=list)
    transitions: list = dataclasses.field(default_factory=list)
    agreement_compliant: dict = dataclasses.field(default_factory=dict)
    predicted: dict = dataclasses.field(default_factory=dict)
    k_by_family: dict = dataclasses.field(default_factory=dict)
    k_factors: list = dataclasses.field(default_factory=list)
    orders: list = dataclasses.field(default_factory=list)
    prediction_check: list = dataclasses.field(default_factory=list)

    def family_k(self, family: str) -> list[float]:
        """The K axis of ``family`` (its ladder from K*, else the map's K values)."""
        return list(self.k_by_family.get(family) or self.stiffness_numbers)

    def ie_star(self) -> dict:
        """family -> K (str) -> I_e* (value, low, high, ci_low, ci_high, kind, criterion)."""
        return {f: {k: cell["ie_star"] for k, cell in by_k.items()} for f, by_k in self.agreement.items()}

    def validation_keys(self) -> dict:
        """This study's keys of ``validation.json``: ``ie_star_by_stiffness`` (family -> K ->
        I_e* with bracket ``low``/``high``, bootstrap ``ci_low``/``ci_high`` and ``kind``), the
        same against the compliant-drive reference (``ie_star_by_stiffness_compliant``), the
        geometry's prediction (``predicted_drive_limits``: family -> ``k_star``, ``ie_star``,
        ``limit``) and ``stiffness_map`` (the agreement grid with n_ok / n per cell, the
        energy and slip tables)."""
        return {
            "ie_star_by_stiffness": self.ie_star(),
            "ie_star_by_stiffness_compliant": self.ie_star_compliant(),
            "predicted_drive_limits": {
                f: {k: d[k] for k in ("k_star", "ie_star", "limit")} for f, d in self.predicted.items()
            },
            "stiffness_map": self.as_dict(),
            "convergence_to_theory": self.orders,
            "predicted_vs_measured": self.prediction_check,
        }

    def as_dict(self) -> dict:
        """The ``validation.json`` entry (the slip samples stay out: the figure holds them)."""
        return {
            "ie": self.ie,
            "K": self.stiffness_numbers,
            "families": self.families,
            "starts_per_preset": self.starts_per_preset,
            "agreement": self.agreement,
            "energy": self.energy,
            "slip": self.slip,
            "tails": self.tails,
            "transitions": self.transitions,
            "agreement_compliant": self.agreement_compliant,
            "predicted": self.predicted,
            "k_by_family": self.k_by_family,
            "k_factors": self.k_factors,
            "orders": self.orders,
            "prediction_check": self.prediction_check,
        }

    def ie_star_compliant(self) -> dict:
        """:meth:`ie_star` against the compliant-drive reference (``agreement_compliant``)."""
        return {
            f: {k: cell["ie_star"] for k, cell in by_k.items()}
            for f, by_k in self.agreement_compliant.items()
        }


def subset_starts(fam: FamilySpec, n: int) -> FamilySpec:
    """``fam`` with at most ``n`` of its y starts, spread over its list (first and last kept),
    on one surface per preset: its first seed and generator variant (the map's many cells
    multiply every surface's cost; :func:`~spine_mj.validate.convergence.thin_starts`)."""
    seeds = fam.seeds[:1] if fam.seeds else fam.seeds
    return dataclasses.replace(thin_starts(fam, n), seeds=seeds, variants=fam.variants[:1])


def stiffness_map(plan: ValidationPlan, runner: StudyRunner) -> StiffnessMapResult:
    """Study 7: the spring drive over ``plan.stiffness_map.ie`` x ``plan.stiffness_map.k``
    on ``plan.stiffness_map.families`` (an empty grid runs nothing).

    Parameters
    ----------
    plan : ValidationPlan
        The validation's sizes (:data:`PLANS`).
    runner : StudyRunner
        Runs the study's sweeps into resumable stores under the output folder.

    Returns
    -------
    StiffnessMapResult
    """
    runner.study = "stiffness_map"
    ies = [float(v) for v in plan.stiffness_map.ie]
    ks = [float(v) for v in plan.stiffness_map.k]
    fams = [f for f in plan.families if f.name in plan.stiffness_map.families]
    empty = StiffnessMapResult(ies, ks, [f.name for f in fams], plan.stiffness_map.starts, {}, [], [])
    if not ies or not (ks or plan.stiffness_map.k_factors) or not fams:
        return empty
    runs, samples, jobs, k_by_family = [], {}, [], {}
    subs = {
        fam.name: subset_starts(plan.stiffness_map.map_family(fam), plan.stiffness_map.starts) for fam in fams
    }
    with runner.phase("predicted drive limits of the families"):
        predicted = families_limits(plan, list(subs.values()), workers=runner.n_workers)
    for fam in fams:
        sub = subs[fam.name]
        deep = (
            subset_starts(sub, plan.stiffness_map.deep_starts) if plan.stiffness_map.deep_starts > 0 else sub
        )
        fks = family_k_axis(predicted[fam.name], plan.stiffness_map.k_factors) or ks
        k_by_family[fam.name] = fks
        for preset in fam.presets:
            drives = [("", {"protocol": "spring", "ie": ies, "K": fks})]
            if deep_ie := list(plan.stiffness_map.deep_ie):
                deep_k = plan.stiffness_map.deep_k_axis(fam.name, fks)
                drives.append(("-deep", {"protocol": "spring", "ie": deep_ie, "K": deep_k}))
            for tag, drive in drives:
                starts = sub if not tag or plan.stiffness_map.deep_starts <= 0 else deep
                doc = family_doc(
                    starts,
                    name=f"stiffness-map-{preset}{tag}",
                    preset=preset,
                    drive=drive,
                    grid=preset_grid(plan, starts, preset),
                )
                jobs.append((fam.name, preset, f"{preset}{tag}", doc))
    # every preset's sweep at once: the workers stay busy across the sweeps' ends
    done = runner.many([(doc, f"stiffness_map/{name}") for _, _, name, doc in jobs], "the (I_e, K) map")
    for (family, preset, _, _), (df, store) in zip(jobs, done):
        with runner.phase(f"slip events and energy on {preset}"):
            runs.append(_run_rows(df, store, family, preset, samples))
    table = pd.concat(runs, ignore_index=True)
    agreement = agreement_map(table, n_boot=plan.bootstrap)
    pooled = {k: {n: np.concatenate(v) for n, v in d.items()} for k, d in samples.items()}
    slip = slip_rows(table)
    return StiffnessMapResult(
        ie=sorted(set(ies) | {float(v) for v in plan.stiffness_map.deep_ie}),
        stiffness_numbers=sorted({k for v in k_by_family.values() for k in v}),
        families=[f.name for f in fams],
        starts_per_preset=plan.stiffness_map.starts,
        agreement=agreement,
        energy=energy_rows(table),
        slip=slip,
        slip_samples=pooled,
        tails=tail_rows(pooled),
        transitions=slip_transitions(slip),
        agreement_compliant=agreement_map(
            table.assign(agree=table["agree_compliant"], frechet=table["frechet_compliant"]),
            n_boot=plan.bootstrap,
        ),
        predicted=predicted,
        k_by_family=k_by_family,
        k_factors=[float(f) for f in plan.stiffness_map.k_factors],
        orders=order_rows(agreement, predicted),
        prediction_check=prediction_check(agreement, predicted),
    )


#: A cell of the map is stick-slip when its runs slip at least this often per L_c advanced.
SLIPS_PER_LC = 0.5


def tail_rows(samples: dict) -> list[dict]:
    """The tail fit of each series of ``samples`` (``(ie, K)`` -> quantity -> values)."""
    rows = []
    for (ie, k), d in sorted(samples.items()):
        for name, values in d.items():
            rows.append({"ie": float(ie), "K": float(k), "quantity": name, **fit_tail(values)})
    return rows


def slip_transitions(slip: list[dict]) -> list[dict]:
    """Per I_e of the map's ``slip`` rows: the largest K with at least :data:`SLIPS_PER_LC`
    slip events per L_c, the next K of the grid (NaN where none), and their geometric mean."""
    out = []
    for ie in sorted({r["ie"] for r in slip}):
        rows = sorted((r for r in slip if r["ie"] == ie), key=lambda r: r["K"])
        slips = [
            r["K"]
            for r in rows
            if np.isfinite(r["slip_events_per_lc"]) and r["slip_events_per_lc"] >= SLIPS_PER_LC
        ]
        low = max(slips) if slips else float("nan")
        above = [r["K"] for r in rows if not slips or r["K"] > low]
        high = min(above) if above else float("nan")
        mid = float(np.sqrt(low * high)) if slips and above else float("nan")
        out.append({"ie": float(ie), "k_low": low, "k_high": high, "k_transition": mid})
    return out


def _length_m(preset: str) -> float:
    """Metres per surface unit of ``preset`` (the rig's scale of a dimensionless surface)."""
    surface = presets.make_surface(preset)
    return sim.DEFAULT_LENGTH_SCALE_M if surface.unit == "1" else 1.0


def _run_rows(df: pd.DataFrame, store, family: str, preset: str, samples: dict) -> pd.DataFrame:
    """One row per MuJoCo run of a preset's sweep: agreement, locks, energy and slip numbers
    (energies in F_p L_c, lengths in L_c); slip events of :data:`SLIP_FAMILIES` runs
    without engine trouble go into ``samples`` under ``(ie, K)``."""
    fp = MASS_KG * GRAVITY
    unit_m = _length_m(preset)
    mj = df[df["analysis"] == "engine"]
    comp = df[df["analysis"] == "compare"].set_index(["case_id", "start"])
    rows = []
    for case_id, grp in mj.groupby("case_id", sort=False):
        traces = mujoco_traces(store, case_id)
        qs = _streamline_traces(store, case_id)
        for _, r in grp.iterrows():
            s = int(r["start"])
            c = comp.loc[(case_id, s)]
            lc = float(r["char_length"])
            ie, k = float(r["ie"]), float(r["K"])
            row = {
                "family": family,
                "surface": r["surface"],
                "ie": ie,
                "K": k,
                "start": s,
                "start_x": float(r["start_x"]),
                "start_y": float(r["start_y"]),
                "agree": c["agree"],
                "agree_lock": c["agree_lock"],
                "frechet": float(c["frechet"]),
                "agree_compliant": c.get("agree_compliant", np.nan),
                "frechet_compliant": float(c.get("compliant_frechet", np.nan)),
                "engine_trouble": r["end_reason"] == "engine_trouble",
                "mj_locked": bool(r["self_locked"]),
            }
            row.update(_energy_and_slip(traces.get(s), qs.get(s), lc, unit_m, fp, float(r["stiffness_n_m"])))
            ev = row.pop("events")
            if family in SLIP_FAMILIES and ev is not None and not row["engine_trouble"]:
                d = samples.setdefault((ie, k), {"jump_lc": [], "force_drop_fp": []})
                d["jump_lc"].append(ev.jump_lengths)
                d["force_drop_fp"].append(ev.force_drops)
            rows.append(row)
    return pd.DataFrame(rows)


def _streamline_traces(store, case_id: str) -> dict[int, pd.DataFrame]:
    """The stored streamlines of a case (start -> ``x``, ``kappa`` by step); empty without."""
    try:
        tr = sweep.load_trajectories(store, case_id, analysis="quasistatic", columns=["x", "kappa"])
    except SpineInputError:
        return {}
    return {int(s): g.sort_values("step") for s, g in tr.groupby("start")}


def _energy_and_slip(tr, qs, lc: float, unit_m: float, fp: float, k_n_m: float) -> dict:
    """Energy and slip numbers of one run from its MuJoCo trace ``tr`` and streamline ``qs``
    (NaN where either is missing): the spring energy released over the slip events and the
    streamline's quasistatic work, in F_p L_c, with the x advance of each path in L_c."""
    nan = float("nan")
    out = {
        "release_fplc": nan,
        "advance_lc": nan,
        "qs_work_fplc": nan,
        "qs_advance_lc": nan,
        "slip_events": nan,
        "slip_time_fraction": nan,
        "events": None,
    }
    lc_m = lc * unit_m
    if tr is not None and len(tr) > 1:
        force = tr["drive_force_n"].to_numpy(dtype=float)
        ev = slip_statistics(
            tr["time_s"],
            tr["x"] / lc,
            tr["y"] / lc,
            force / fp,
            tr["motion"],
        )
        spans = list(zip(ev.onset_indices.tolist(), ev.stop_indices.tolist()))
        x = tr["x"].to_numpy(dtype=float)
        out.update(
            release_fplc=elastic_release_j(force, k_n_m, spans) / (fp * lc_m),
            advance_lc=float(x[-1] - x[0]) / lc,
            slip_events=float(ev.count),
            slip_time_fraction=float(np.mean(tr["motion"].to_numpy() == SLIPPING)),
            events=ev,
        )
    if qs is not None and len(qs) > 1:
        xq = qs["x"].to_numpy(dtype=float)
        out.update(
            qs_work_fplc=quasistatic_work_j(qs["kappa"], xq * unit_m, fp) / (fp * lc_m),
            qs_advance_lc=float(xq[-1] - xq[0]) / lc,
        )
    return out


def _cells(runs: pd.DataFrame, *keys: str):
    """Groups of ``runs`` by ``keys`` in sorted order, with float keys."""
    for key, grp in runs.groupby(list(keys), sort=True):
        yield key, grp.sort_values(["surface", "start"])


def agreement_map(runs: pd.DataFrame, *, n_boot: int, rng=12345) -> dict:
    """Agreement per (family, K, I_e) and I_e*(K) per family, from per-run rows.

    Parameters
    ----------
    runs : DataFrame
        One row per run: ``family``, ``K``, ``ie``, ``surface``, ``start``, ``agree``
        (outcome agreement; missing counts as disagreeing), ``frechet`` (/ L_c) and
        ``engine_trouble``.
    n_boot : int
        Bootstrap resamples of the starts for the I_e* interval.

    Returns
    -------
    dict
        family -> K (str, ``"%g"``) -> ``ie``, ``agreement`` (fraction of runs),
        ``median_frechet``, ``passes`` (the :data:`CRITERION` at that I_e), ``n_ok`` (runs
        without engine trouble), ``n`` (runs) per I_e, and ``ie_star``: the criterion's
        :class:`~spine_mj.validate.ie_star.IeStar` dict with ``criterion`` (NaN, kind
        ``"not measured"``, with fewer than two I_e values). It is read on the I_e values
        every start ran; where it fails already at the lowest of those and deeper I_e values
        ran on a subset of the starts (``start_x``, ``start_y`` tell which), it is read again
        over every I_e on that subset, with ``starts``: how many.
    """
    out: dict = {}
    for (fam, k), grp in _cells(runs, "family", "K"):
        ies, ag, med, n_ok, n, amat, fmat = [], [], [], [], [], [], []
        for (ie,), cell in _cells(grp, "ie"):
            a = cell["agree"].fillna(False).astype(bool).to_numpy(dtype=float)
            f = cell["frechet"].to_numpy(dtype=float)
            ies.append(float(ie))
            ag.append(float(a.mean()))
            with quiet_nan_warnings():
                med.append(float(np.nanmedian(f)))
            n_ok.append(int((~cell["engine_trouble"].astype(bool)).sum()))
            n.append(len(cell))
            amat.append(a)
            fmat.append(f)
        # a resample needs one start set across I_e: the grid's, not a deeper I_e's subset
        full = [i for i, a in enumerate(amat) if len(a) == max(len(b) for b in amat)]
        if len(full) >= 2:
            star = _criterion_star(ies, amat, fmat, full, n_boot=n_boot, rng=rng)
            if star["kind"] == "below" and len(full) < len(ies):
                star = _deep_star(grp, ies, star, n_boot=n_boot, rng=rng)
        else:
            star = {"value": float("nan"), "kind": "not measured", "criterion": "fewer than two I_e values"}
        passes = [passes_criterion(a_, f_) for a_, f_ in zip(ag, med)]
        out.setdefault(fam, {})[f"{float(k):g}"] = {
            "ie": ies,
            "agreement": ag,
            "median_frechet": med,
            "passes": passes,
            "n_ok": n_ok,
            "n": n,
            "ie_star": star,
        }
    return out


def _criterion_star(ies, amat, fmat, rows, *, n_boot: int, rng) -> dict:
    """I_e* of :data:`CRITERION` over the I_e values ``rows`` of one cell's matrices."""
    return ie_star_by_criterion(
        np.array([ies[i] for i in rows]),
        np.array([amat[i] for i in rows]),
        np.array([fmat[i] for i in rows]),
        n_boot=n_boot,
        rng=rng,
    )[CRITERION]


def _deep_star(grp: pd.DataFrame, ies: list[float], star: dict, *, n_boot: int, rng) -> dict:
    """I_e* of one K whose grid fails already at its lowest I_e (``star``, kind ``below``),
    read over every I_e on the starts that ran at all of them (matched by surface and point:
    a deeper sweep numbers its starts anew): a deep cell that passes brackets I_e* from
    below. ``star`` where the rows have no start points or fewer than two in common."""
    if not {"start_x", "start_y"} <= set(grp):
        return star
    key = (
        grp["surface"].astype(str)
        + "@"
        + grp[["start_x", "start_y"]].round(9).astype(str).agg(",".join, axis=1)
    )
    common = set.intersection(*(set(key[grp["ie"] == ie]) for ie in ies))
    if len(common) < 2:
        return star
    sub = grp[key.isin(common)].assign(_key=key)
    amat, fmat = [], []
    for ie in ies:
        cell = sub[sub["ie"] == ie].drop_duplicates("_key").sort_values("_key")
        amat.append(cell["agree"].fillna(False).astype(bool).to_numpy(dtype=float))
        fmat.append(cell["frechet"].to_numpy(dtype=float))
    deep = _criterion_star(ies, amat, fmat, range(len(ies)), n_boot=n_boot, rng=rng)
    return {**deep, "starts": len(common)}


def grid_lowest_ie(runs: pd.DataFrame) -> float:
    """The lowest I_e every K of ``runs`` ran at (the grid's, not a deeper one of the
    stiffest K)."""
    return float(runs.groupby("K")["ie"].min().max())


def energy_rows(runs: pd.DataFrame) -> list[dict]:
    """Per K at the lowest I_e of ``runs`` (where inertia plays no part), pooled over the
    families: spring energy released at breakaways per L_c the MuJoCo tip advanced, the
    streamline's quasistatic work per L_c it advanced (both in F_p), their ratio, slip
    events per L_c, and outcome agreement, with ``n_ok`` / ``n`` runs.

    ``runs`` has the per-run columns of :func:`agreement_map` plus ``release_fplc``,
    ``advance_lc``, ``qs_work_fplc``, ``qs_advance_lc`` and ``slip_events``.
    """
    if runs.empty:
        return []
    low = runs[np.isclose(runs["ie"], grid_lowest_ie(runs))]
    rows = []
    for (k,), g in _cells(low, "K"):
        ok = g[~g["engine_trouble"].astype(bool)]
        adv = ok["advance_lc"].clip(lower=0).sum()
        qadv = ok["qs_advance_lc"].clip(lower=0).sum()
        release = ok["release_fplc"].sum() / adv if adv > 0 else float("nan")
        work = ok["qs_work_fplc"].sum() / qadv if qadv > 0 else float("nan")
        rows.append(
            {
                "K": float(k),
                "ie": float(low["ie"].iloc[0]),
                "n_ok": len(ok),
                "n": len(g),
                "release_per_lc": release,
                "qs_work_per_lc": work,
                "release_over_work": release / work if work > 0 else float("nan"),
                "slip_events_per_lc": ok["slip_events"].sum() / adv if adv > 0 else float("nan"),
                "agreement": float(g["agree"].fillna(False).astype(bool).mean()),
            }
        )
    return rows


def slip_rows(runs: pd.DataFrame) -> list[dict]:
    """Per (I_e, K): slip events per L_c advanced and the fraction of time slipping over
    the :data:`SLIP_FAMILIES` runs without engine trouble (``n_ok`` / ``n``), and the
    fraction of quasistatic traps MuJoCo skips over every family's runs without engine
    trouble (``traps``: streamline self-locks; ``skipped``: of those, runs where MuJoCo did
    not lock).

    ``runs`` has the columns of :func:`energy_rows` plus ``agree_lock`` and ``mj_locked``.
    """
    if runs.empty:
        return []
    rows = []
    for (ie, k), g in _cells(runs, "ie", "K"):
        fine = g[~g["engine_trouble"].astype(bool)]  # a run the engine lost neither locks nor skips
        qs_locked = quasistatic_locked(fine["agree_lock"].to_numpy(), fine["mj_locked"].to_numpy())
        skipped = qs_locked & ~fine["mj_locked"].astype(bool).to_numpy()
        s = g[g["family"].isin(SLIP_FAMILIES)]
        ok = s[~s["engine_trouble"].astype(bool)]
        adv = ok["advance_lc"].clip(lower=0).sum()
        with quiet_nan_warnings():
            frac = float(np.nanmean(ok["slip_time_fraction"])) if len(ok) else float("nan")
        rows.append(
            {
                "ie": float(ie),
                "K": float(k),
                "n_ok": len(ok),
                "n": len(s),
                "slip_events_per_lc": float(ok["slip_events"].sum() / adv) if adv > 0 else float("nan"),
                "slip_time_fraction": frac,
                "traps": int(qs_locked.sum()),
                "skipped": int(skipped.sum()),
                "trap_skip_rate": float(skipped.sum() / qs_locked.sum()) if qs_locked.sum() else float("nan"),
            }
        )
    return rows

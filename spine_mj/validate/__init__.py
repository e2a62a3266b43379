"""The validation harness: MuJoCo against the quasistatic streamline across inertia numbers.

Ten studies (the registry :data:`~spine_mj.validate.studies.STUDIES`), each a function
that runs its MuJoCo cases through the sweep runner (:func:`spine_mj.sweep.run_sweep`, one
resumable store per study under ``out/sweeps/``, so a killed validation resumes where it
stopped) and returns a typed result with the numbers and the data of its figures
(``as_dict()`` gives the keys of ``validation.json``):

1. :func:`static_map` - breakaway ratio ``kappa_mj / kappa`` of the static probe on inclined
   planes over slope angle and azimuth (engaged, self-lock and slip regions), per engine
   setting.
2. :func:`quasistatic_limit` - spring-drive paths at the lowest inertia number against the
   streamline traced on the surface the tip touches (MuJoCo's facets dilated by the tip,
   the like-for-like comparison) and on the smooth surface (the difference is the
   geometry), per surface family; the engine settings that limit agreement varied one at
   a time.
3. :func:`boundary` - agreement against ``I_e`` for the spring and ramp drives and the
   ``I_e*`` where it breaks, with a bracketing interval and a bootstrap over starts.
4. :func:`stick_slip` - drive-force curves, slip-event statistics and trap skipping against
   ``I_e`` and spring stiffness.
5. :func:`sandpaper` - P36 / P60 / P600 analogs with a 25 um tip: path waviness and force
   peaks.
6. :func:`fractal_lock` - the self-lock rate against the Hurst exponent H on fractal
   surfaces (the paper's Figs. 7E and 9), streamline beside MuJoCo at the quasistatic
   corner and at one dynamic I_e, with binomial intervals.
7. :func:`stiffness_map` - the spring drive's agreement over (I_e, K), ``I_e*(K)`` per
   family, the elastic energy released at breakaway against the quasistatic work, and
   slip-size / force-drop distributions.
8. :func:`ground_truth` - MuJoCo's spring drive against the closed forms of
   :mod:`spine_mj.theory.tomlinson` (spring-block, Prandtl-Tomlinson, crest lift-off).
9. :func:`array_study` - spine arrays dragged over rough surfaces, and the paper's
   staggered-array conjecture in dynamics.
10. :func:`~spine_mj.validate.engines.engines_study` - the closed forms (static kappa,
    spring-block, Prandtl-Tomlinson, crest lift-off, V-groove and Dai wedges, creep) in
    MuJoCo beside Bullet, where the ``[bullet]`` extra is installed (without it, one line
    says so).

:func:`run_validation` runs them all for a :class:`ValidationPlan` (``"quick"``, ``"full"``
or the test-size ``"smoke"``), writes ``report.md`` with PNG figures and ``validation.json``.

Lengths in the metrics are in units of the surface's characteristic length ``L_c``
(:func:`spine_mj.roughness.characteristic_length`), forces in units of the preload ``F_p``.

Modules: :mod:`~spine_mj.validate.plans` (plans, targets, constants),
:mod:`~spine_mj.validate.study_runner` (runs a study's sweep configs into resumable
stores), :mod:`~spine_mj.validate.sweep_configs` (the sweep configs the studies share),
:mod:`~spine_mj.validate.paths` (streamlines on the tip-dilated surface, path metrics),
:mod:`~spine_mj.validate.ie_star` (I_e* estimators and bootstrap),
:mod:`~spine_mj.validate.ramp_pilot` (a ramp's duration from a pilot run), one module per
study, :mod:`~spine_mj.validate.report` (one report module per study, named like it),
:mod:`~spine_mj.validate.studies` (the registry: name, run function, result type, report
module) and :mod:`~spine_mj.validate.suite` (:func:`run_validation`).
"""

import lazy_loader as _lazy

__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)

"""The quasistatic and closed-form models: what the MuJoCo rig is validated against.

Nothing here imports MuJoCo or :mod:`spine_mj.sim` (a test checks the import graph), so the
theory runs wherever numpy and numba do.

- :mod:`~spine_mj.theory.engagement`: the engagement ratio kappa of one contact (paper
  Eq. 2) and of a tip wedged in a crease;
- :mod:`~spine_mj.theory.multicontact`: the hold force of a tip touching several facets;
- :mod:`~spine_mj.theory.streamline`: quasistatic paths of a tip under gravity and a drive;
- :mod:`~spine_mj.theory.compliant`: the same behind a spring drive (stick-slip, folds);
- :mod:`~spine_mj.theory.convexity`: sectional and Hessian classification (Eqs. 6-10);
- :mod:`~spine_mj.theory.drive_limits`: the drive stiffness and inertia number a surface
  allows before the quasistatic picture fails;
- :mod:`~spine_mj.theory.tomlinson`, :mod:`~spine_mj.theory.tomlinson_dynamics`: closed
  forms and a reference integrator for the Prandtl-Tomlinson corrugation;
- :mod:`~spine_mj.theory.motion`: stuck, sliding and slipping relative to the drive, and the
  slip events they make (of a MuJoCo run and of the reference integrator alike);
- :mod:`~spine_mj.theory.avalanches`: the overdamped and inertial quasistatic references of
  stick-slip on a landscape (the ABBM track's avalanches);
- :mod:`~spine_mj.theory.energy`: energy budget of a stick-slip event;
- :mod:`~spine_mj.theory.array_reference`: the quasistatic hold curve of a spine array;
- :mod:`~spine_mj.theory.targets`: how close a dynamic run must come to count as agreeing;
- :mod:`~spine_mj.theory.agreement`: the metrics that say so (Frechet distance, outcome and
  kappa agreement, capture rate, why a run and its reference part).
"""

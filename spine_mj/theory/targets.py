"""What "agree" means at the quasistatic corner, for sweeps and validation alike.

A dynamic run agrees with the quasistatic model when the share of runs with the same
outcome is at least :data:`OUTCOME_TARGET` and the path deviation (discrete Frechet
distance over ``L_c``, :func:`spine_mj.theory.agreement.frechet_distance`) is at most
:data:`FRECHET_TARGET`. The theory uses the second too: the lag limit of
:func:`spine_mj.theory.drive_limits.drive_limits` is the inertia number at which a path
lags its streamline by this much.
"""

#: Outcome agreement: at least this share of the runs.
OUTCOME_TARGET = 0.95
#: Path deviation: at most this (Frechet distance over ``L_c``).
FRECHET_TARGET = 0.1

__all__ = ["FRECHET_TARGET", "OUTCOME_TARGET"]

"""Stick-phase fast-forward: the rule the force ramp and the static probe share.

At a low force rate most engine steps integrate a tip that does not move while the drive
force climbs. Once the tip has been still for :data:`QUIET_STEPS` steps on one contact
normal (tangential speed at most ``Detection.stick_speed_m_s``, the normal unchanged
within :data:`NORMAL_TOL`) with the noslip solver on, :class:`StickFastForward` predicts
the breakaway force ``F_b = kappa_of_normal(n, mu) F_p`` (the lock rule the streamline
uses, :func:`spine_mj.theory.engagement.kappa_of_normal`; infinite in the self-lock region) and
lets the force climb to ``min((1 - margin) F_b, F_b - NOMINAL_STEPS increments,
kappa_cap F_p)`` in :data:`RISE_STEPS` steps. A tip that moves during the climb
(tangential speed above the stick speed, or contact lost) makes the caller go back to
before the motion and on at the nominal rate.

After the climb, the static probe goes on at the nominal rate through breakaway. The
ramp, which keeps checkpoints every :data:`CHECKPOINT_STEPS` steps, goes on in an
approach stage at :data:`APPROACH_RATE` nominal increments per step up to the cap: the
breakaway happens in it, the tip's motion sends the run back 8 to 16 steps (64 to 128
nominal increments below the breakaway force) and the nominal rate takes it through the
breakaway from there. A stuck tip gets an approach alone where the climb would not help:
held beyond the predicted breakaway (wedged between hfield facets, whose deepest normal
predicts too little), or more than a rollback's worth of increments below it. Stepping
the margin at the nominal rate cost ~1000 steps per ramp cycle at kappa ~ 5 and I_e =
1e-4; the approach and its rollback cost ~250.

Users: :mod:`spine_mj.sim.ramp` (every stick phase of the ramp with reset) and
:mod:`spine_mj.sim.rollout` (the static probe's one stick phase, after settling, and every
stick phase of a spring drive that a piece of its rollout ends in: the spring's force
``k (X - x)`` on a stuck tip is the ramp's force, its rate ``k V``, and the carriage's
advance is what climbs). What the equivalence neglects is written in the ramp's module
docstring and the README.
"""

from __future__ import annotations

import math

import numpy as np

from spine_mj.theory.engagement import SELF_LOCK, kappa_of_normal

#: Steps the tip must be still on one normal before a fast-forward phase starts.
QUIET_STEPS = 8
#: Steps over which a fast-forward phase raises the force (50 contact time constants).
RISE_STEPS = 100
#: Nominal-rate steps a phase leaves before the predicted breakaway, at least (50 contact
#: time constants: at a fast rate the 3 % margin alone is a few steps, and the contact
#: loaded by the rise breaks away late).
NOMINAL_STEPS = 100
#: Largest change of a unit normal (any component) that counts as the same normal.
NORMAL_TOL = 1e-4
#: Rate of the approach stage, in nominal increments per step (see :class:`StickFastForward`).
APPROACH_RATE = 8.0
#: Steps between checkpoints inside a phase (a rollback goes back 8 to 16 steps).
CHECKPOINT_STEPS = 8


class StickFastForward:
    """Decides when the ramp may climb fast and how far (see the module docstring).

    Parameters
    ----------
    mu : float
        Friction coefficient of the contact.
    preload_n, cap_n : float
        F_p [N] and the largest force ``kappa_cap F_p`` [N].
    margin : float
        The climb stops at ``(1 - margin)`` of the predicted breakaway force.
    stick_speed_m_s, move_speed_m_s : float
        Still below the first; a slip (which allows a new phase) above the second.
    approach_rate : float or None
        For a caller that rolls back to checkpoints (the ramp): after the climb the phase
        goes on at ``approach_rate`` nominal increments per step up to the cap, so that the
        breakaway itself happens in it and is rolled back (8 to 16 steps, a force
        ``approach_rate`` times that many increments lower) to be taken at the nominal
        rate, instead of covering the whole margin at that rate. A stuck tip that the
        climb would not help gets such an approach alone: where it holds beyond the
        predicted breakaway (wedged between facets, whose deepest normal predicts too little)
        or lies more than a rollback's worth of increments below it. None: the nominal
        rate takes over after the climb.
    """

    def __init__(self, *, mu, preload_n, cap_n, margin, stick_speed_m_s, move_speed_m_s, approach_rate=None):
        self.mu, self.preload_n, self.cap_n, self.margin = mu, preload_n, cap_n, margin
        self.stick, self.slip = stick_speed_m_s, move_speed_m_s
        self.approach_rate = approach_rate
        self.active, self.blocked, self.quiet = False, False, 0
        self.target_n, self.step_n, self.approach_to_n = 0.0, 0.0, 0.0
        self.blocked_to_n = 0.0  # force at which the last phase ended
        self.normal0 = np.zeros(3)
        self.prev = np.zeros(3)
        self.phases = self.rollbacks = 0

    def watch(self, vt: float, normal: np.ndarray, contact: bool, force: float, step_n: float) -> str:
        """Verdict on one ramping step: ``"start"`` (a phase begins), ``"rollback"`` (the tip
        moved during a phase), or ``""``. ``normal`` points out of the surface."""
        same = contact and float(np.abs(normal - self.prev).max()) <= NORMAL_TOL
        self.prev = normal.copy()
        if self.active:
            if not contact or vt > self.stick:
                self._end(force)
                self.rollbacks += 1
                return "rollback"
            if float(np.abs(normal - self.normal0).max()) > NORMAL_TOL:
                self._end(force)
            elif force >= self.target_n:
                if self.approach_rate is not None and self.approach_to_n > self.target_n:
                    self.target_n, self.step_n = self.approach_to_n, self.approach_rate * step_n
                else:
                    self._end(force)
            return ""
        # a new phase once the tip has slipped, or once the nominal ramp has carried the
        # force past where the last phase ended (the tip moved there without slipping)
        if vt > self.slip or force > self.blocked_to_n:
            self.blocked = False
        self.quiet = self.quiet + 1 if (same and vt <= self.stick) else 0
        if self.blocked or self.quiet < QUIET_STEPS:
            return ""
        k, region = kappa_of_normal(normal, self.mu)
        f_b = math.inf if int(region) == SELF_LOCK else float(k) * self.preload_n
        if not math.isfinite(f_b) and int(region) != SELF_LOCK:
            return ""  # the slip region: no hold to predict
        # leave the nominal ramp at least NOMINAL_STEPS before the predicted breakaway, so
        # the contact loaded by the fast rise settles before it is tested
        target = min((1 - self.margin) * f_b, f_b - NOMINAL_STEPS * step_n, self.cap_n)
        self.approach_to_n = self.cap_n
        if target - force > 2 * RISE_STEPS * step_n:
            self.step_n = (target - force) / RISE_STEPS
        elif (
            self.approach_rate is not None
            and force < self.cap_n
            and (force >= f_b or f_b - force > 2 * CHECKPOINT_STEPS * self.approach_rate * step_n)
        ):
            target, self.step_n = self.cap_n, self.approach_rate * step_n
        else:
            return ""  # the nominal ramp gets there about as fast
        self.active, self.target_n, self.normal0 = True, target, normal.copy()
        self.phases += 1
        return "start"

    def skim(self, vt_max: float, force_max: float) -> None:
        """Rows the caller did not :meth:`watch` one by one (a spring run's piece, of which
        only the last rows are watched): unblock as :meth:`watch` would have, where the tip
        slipped (``vt_max``) or the force passed where the last phase ended (``force_max``)."""
        if vt_max > self.slip or force_max > self.blocked_to_n:
            self.blocked = False

    def finish(self, force: float) -> None:
        """End the phase at ``force``, where the caller's climb ended (a spring's climb
        stops a fraction of a step's increment short of the target)."""
        self._end(force)

    def _end(self, force: float) -> None:
        self.active, self.blocked, self.quiet, self.blocked_to_n = False, True, 0, force


def fast_forward_on(drive, engine, tip) -> bool:
    """Whether ``drive`` fast-forwards its stick phases on this engine and tip: it asks for
    it (``drive.fast_forward``), noslip makes the stick rigid (without it friction creeps at
    any load, so a stuck tip still moves) and there is friction to hold it."""
    return bool(getattr(drive, "fast_forward", False)) and engine.noslip_iterations > 0 and tip.mu_s > 0

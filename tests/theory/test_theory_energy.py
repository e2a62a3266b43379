"""Energy accounting: the work-energy theorem on recorded runs, spring release closed forms."""

import numpy as np
import pytest
from sim_rigs import MU, flat_rig

from spine_mj.sim import SpringDrive
from spine_mj.sim.drives import stiffness_n_m
from spine_mj.theory.energy import elastic_release_j, energy_budget, quasistatic_work_j


def test_spring_on_a_flat_plane_accounts_for_the_carriage_work():
    """Flat ground, spring drive: the carriage's work goes into the spring and onto the tip
    (an identity of the recorded force and positions), and the tip's share is about
    mu F_p per metre travelled, all of it dissipated (no height change, no net speed)."""
    rig = flat_rig()
    drive = SpringDrive(speed_m_s=0.005, duration_s=2.0)
    res = rig.run(drive, start=(-0.04, 2.3e-4))
    budget = energy_budget(res, stiffness_n_m=stiffness_n_m(drive, rig.scales))
    # F = k (x_c - x) sampled every step: trapezoid and finite-difference error < 1 %
    assert abs(budget.spring_residual_j) < 0.01 * budget.carriage_work_j
    i0 = res.drive_start_index
    distance = res.position_m[-1, 0] - res.position_m[i0, 0]
    fp = rig.scales.preload_n
    # the tip sticks and slips under a force that never exceeds mu F_p: at most mu F_p per
    # metre, and more than half of it on average (the force ramps up from 0 at the start)
    assert 0.5 * MU * fp * distance < budget.drive_work_j < 1.02 * MU * fp * distance
    assert budget.contact_dissipation_j == pytest.approx(budget.drive_work_j, rel=0.01)
    # what a breakaway releases is bounded by the largest energy the spring ever held
    k = stiffness_n_m(drive, rig.scales)
    held = (res.drive_force_n[i0:] ** 2).max() / (2 * k)
    n_slips = len(res.slip_events)
    assert 0 <= budget.elastic_release_j <= n_slips * held * (1 + 1e-12)


def test_elastic_release_closed_form():
    force = np.array([0.0, 2.0, 4.0, 3.0, 1.0, 1.0, 3.0, 2.0])
    events = [(2, 4), (6, 7)]
    k = 5.0
    # (4^2 - 1^2) / 2k for the first slip, (3^2 - 2^2) / 2k for the second
    expected = (16 - 1) / (2 * k) + (9 - 4) / (2 * k)
    assert elastic_release_j(force, k, events) == pytest.approx(expected)
    with pytest.raises(ValueError, match="stiffness_n_m"):
        elastic_release_j(force, 0.0, events)


def test_quasistatic_work_on_flat_ground_is_mu_fp_distance():
    x = np.linspace(0.0, 0.3, 31)
    assert quasistatic_work_j(np.full_like(x, MU), x, 2.0) == pytest.approx(MU * 2.0 * 0.3)
    kappa = np.full_like(x, MU)
    kappa[10:] = np.inf  # self-locked from x = 0.1: no further quasistatic work
    assert quasistatic_work_j(kappa, x, 2.0) == pytest.approx(MU * 2.0 * (0.1 - 0.005), rel=1e-9)

"""
Stick-slip on a corrugation against Prandtl-Tomlinson
=====================================================

A tip pulled through a spring of stiffness number ``K = k l_s / F_p`` over the corrugation
``z = h sin(2 pi x / lambda)`` is the Prandtl-Tomlinson model with Coulomb friction: the
motion is smooth for ``K > K*`` and sticks and slips below, jumping once per wavelength at
the fold of the quasistatic branch (:class:`spine_mj.theory.tomlinson.Corrugation`; the
physics notes, §6-§7). The MuJoCo spring drive at a small inertia number, against the
compliant-drive streamline (:func:`spine_mj.compliant_streamlines`), which is that model
traced on the surface the tip's centre rides on. Drawn against the tip's position, the
force follows ``W kappa(x)`` while the tip sticks, and a slip is a horizontal jump.
"""

import matplotlib.pyplot as plt
import numpy as np

import spine_mj as sm
from spine_mj import sim
from spine_mj.theory.tomlinson import Corrugation

mu = 0.5
surface = sm.make_surface("corrugation", n_waves=4, points_per_wave=128)
rig = sim.build_rig(surface, mu=mu)
unit = rig.scales.length_scale_m
l_s = rig.scales.slope_length_m / unit  # surface units
tip = rig.scales.tip_radius_m / unit
k_star = Corrugation(slope_amplitude=0.3, mu=mu, tip_radius=tip).critical_stiffness(l_s)
print(f"K* = {k_star:.3f}")

start = (0.25, 0.0)
fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True, constrained_layout=True)
for ax, factor in zip(axes, (0.5, 2.0)):
    K = factor * k_star
    run = rig.run(sim.build_drive(rig.scales, "spring", ie=1e-4, stiffness_number=K), start=start)
    ref = sm.compliant_streamlines(
        sm.dilate(surface, tip), [start], sm.StreamlineParams(mu=mu), stiffness=K / l_s
    )
    tip_x = np.asarray(run.position_m)[:, 0] / unit
    ax.plot(ref.x, ref.force, "c-", lw=3, label="Prandtl-Tomlinson (compliant streamline)")
    ax.plot(tip_x, run.drive_force_n / rig.scales.preload_n, "k-", lw=0.8, label="MuJoCo spring drive")
    n_slips = len(run.slip_events)
    ax.set_title(f"K = {factor:g} K*: {len(ref.folds.x)} jumps predicted, {n_slips} slips in MuJoCo")
    ax.set_ylabel("drive force / F_p")
axes[0].legend(fontsize="small")
axes[1].set_xlabel("tip position x (wavelengths)")

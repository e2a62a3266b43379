"""The kernel warm-up compiles the signatures a job calls: after it, the real calls of a
comparison (a preset's streamline, the engine's facets and their compliant reference, an
engine run's and a force ramp's analysis, a dilation) compile nothing new."""

from __future__ import annotations

import numpy as np

from spine_mj import presets
from spine_mj.sweep.kernel_warmup import warm_kernels


def _dispatchers():
    from spine_mj.sim import _window_kernel
    from spine_mj.surfaces import _contact_kernel, _dilation_kernel
    from spine_mj.theory import (
        _compliant_kernel,
        _facet_streamline_kernel,
        _kernels,
        _multicontact_kernel,
        agreement,
    )

    return {
        "streamline": _kernels.run_trajectories,
        "facet streamline": _facet_streamline_kernel.run_facets,
        "two-contact rule": _multicontact_kernel.two_contact,
        "compliant": _compliant_kernel.run_compliant,
        "ball on facets": _contact_kernel.ball_on_facets,
        "dilation": _dilation_kernel.ball_rows,
        "frechet": agreement._frechet_kernel,
        "engine windows": _window_kernel.analyse_window,
    }


def test_after_the_warm_up_a_comparison_compiles_nothing_new():
    from spine_mj.sim import RampDrive, Rig, SpringDrive, TipParams
    from spine_mj.surfaces.dilation import ball_dilation, dilate
    from spine_mj.theory import agreement
    from spine_mj.theory._streamline_numpy import _two_contact_kappa
    from spine_mj.theory.compliant import compliant_streamlines
    from spine_mj.theory.streamline import ideal_trajectories, streamlines
    from spine_mj.theory.streamline_types import StreamlineParams

    warm_kernels(1)
    kernels = _dispatchers()
    before = {name: len(k.signatures) for name, k in kernels.items()}
    assert all(before.values()), before

    peak = presets.make_surface("paper-single-peak")
    p = StreamlineParams(mu=0.5, dl=0.05, max_steps=200)
    streamlines(peak, [(-3.0, -1.0)], p)
    ideal_trajectories(presets.make_surface("paper-fractal"), [(-9.0, 0.0)], p)
    dilate(presets.make_surface("paper-fractal"), 0.2)
    rig = Rig(peak, tip=TipParams(mu_s=0.5))
    contact = rig.contact_surface()
    contact.evaluate(np.array([-3.0]), np.array([-1.0]), order=1)
    streamlines(contact, [(-3.0, -1.0)], p)
    _two_contact_kappa(*(np.array([v, v]) for v in (0.2, 0.1, -0.3, 0.0)), 0.5)
    compliant_streamlines(contact, [(-3.0, -1.0)], p, stiffness=1.0)
    drive = SpringDrive(speed_m_s=rig.scales.speed_for(0.1), duration_s=0.02)
    run = rig.run_batch(drive, [(-3.0, -1.0)], nthread=1)
    rig.run(RampDrive(duration_s=0.02), start=(-3.0, -1.0))
    ball_dilation(np.zeros((9, 9)), 0.2, spacing=(0.1, 0.1))  # writable heights
    path = run[0].position_m[:, :2] / rig.length_scale_m
    agreement.path_frechet(path, path[::-1], length_scale=1.0)

    after = {name: len(k.signatures) for name, k in kernels.items()}
    assert after == before

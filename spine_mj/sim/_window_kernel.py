"""Compiled (numba) analysis of a window of recorded rows: the fast path of
:class:`~spine_mj.sim.results.GroupAnalysis`.

One pass over the rows does what three numpy functions do in some seventy passes:
:func:`~spine_mj.sim.recording.sensor_columns` (the SI columns),
:func:`~spine_mj.sim.detection.end_marks` (the first row of each end condition) and
:func:`~spine_mj.sim.detection.normal_lock_marks` (the shared lock rule, carried from one
window to the next). Those stay the reference: ``tests/sim/test_sim_window_kernel.py`` checks
this kernel against them, value for value, on recorded runs and on rows with engine trouble.
Every number is computed with the same floating-point operations in the same order as the
reference (no fast-math), so the two agree to the last bit.

Why it exists: the batch runner analyses each piece on the calling thread while the worker
threads simulate, and on a machine with as many cores as workers every microsecond of
that analysis is taken from the simulation (``benchmarks/bench_rollout.py``).
"""

import math

import numpy as np
from numba import njit

_MAX = np.finfo(np.float64).max


@njit(cache=True, inline="always")
def _finite_or_clipped(x):
    """``np.nan_to_num`` of one number."""
    if math.isnan(x):
        return 0.0
    if math.isinf(x):
        return _MAX if x > 0 else -_MAX
    return x


@njit(cache=True, nogil=True)  # the worker threads go on stepping meanwhile
def analyse_window(
    state,
    sens,
    widths,
    carriage,
    spring,
    adr,
    units,
    prm,
    speed_limit2,
    force_limit,
    firsts,
    held_from,
    out_rows,
    time_s,
    position,
    velocity,
    contact,
    normal,
    contact_point,
    penetration,
    normal_force,
    tangential_force,
    drive_force,
    carriage_x,
    moving,
    tangential_speed,
    marks,
    held_out,
):
    """Columns, end marks and lock-rule carry of the group's runs ``out_rows`` (g,), run
    ``r`` from its row ``firsts[r]`` on for ``widths[r]`` rows: ``state``, ``sens``,
    ``carriage`` and the columns are the group's arrays; the marks (window rows) and the
    per-run inputs are in ``out_rows`` order.

    ``adr``: sensor addresses (tip_pos, tip_vel, contact_net, contact_deepest,
    spring_force, push_force, contact_normal). ``units``: metres, newtons, m/s and seconds per engine unit.
    ``prm``: step [s], domain (xmin, xmax, ymin, ymax, zmin, zmax + span) [m], edge margin
    [m], slip speed [m/s], penetration tolerance [m], the cap's force times (1 - 1e-9) [N],
    mu_s, the self-lock tolerance, the lock rule's rise [N]. ``spring`` (g,)
    marks the runs whose carriage is recorded; ``speed_limit2`` (g,) the squared speed
    limits; ``force_limit`` (g,) the drive force limits [N]; ``held_from`` (g,) the lock
    rule's carry (NaN: none). Writes the columns,
    ``marks`` (g, 10) in :data:`~spine_mj.sim.detection.MARK_KEYS` order (-1: none) and ``held_out`` (g,).
    """
    g = out_rows.size
    p, v, cn, cd, sp, pu, tn = adr[0], adr[1], adr[2], adr[3], adr[4], adr[5], adr[6]
    length, force_n, speed, time_u = units[0], units[1], units[2], units[3]
    dt, xmin, xmax, ymin, ymax, zmin, ztop = prm[0], prm[1], prm[2], prm[3], prm[4], prm[5], prm[6]
    mg, slip_speed, pen_tol, cap = prm[7], prm[8], prm[9], prm[10]
    mu, tol, rise = prm[11], prm[12], prm[13]
    m2 = mu * mu
    nstate, nsens = state.shape[2], sens.shape[2]
    for r in range(g):
        for k in range(marks.shape[1]):
            marks[r, k] = -1
        o = out_rows[r]
        streak = not math.isnan(held_from[r])
        base = held_from[r]
        first = firsts[r]
        for i in range(widths[r]):
            c = first + i
            s = sens[o, c]
            if marks[r, 0] < 0:
                bad = False  # independent tests, not a sum: no chain of dependent additions
                for j in range(nstate):
                    bad |= not math.isfinite(state[o, c, j])
                for j in range(nsens):
                    bad |= not math.isfinite(s[j])
                if bad:
                    marks[r, 0] = i
            touching = s[cd] > 0
            contact[o, c] = touching
            flip = s[cd + 7] < 0
            n0 = -s[cd + 5] if flip else s[cd + 5]
            n1 = -s[cd + 6] if flip else s[cd + 6]
            n2 = -s[cd + 7] if flip else s[cd + 7]
            c0 = _finite_or_clipped(n0) if touching else 0.0
            c1 = _finite_or_clipped(n1) if touching else 0.0
            c2 = _finite_or_clipped(n2) if touching else 0.0
            f0, f1, f2 = -s[cn + 1], -s[cn + 2], -s[cn + 3]
            fn = s[tn] if touching else 0.0
            if touching:
                along = (c0 * f0 + c2 * f2) + c1 * f1
                t0, t1, t2 = f0 - along * c0, f1 - along * c1, f2 - along * c2
                ft = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
            else:
                ft = 0.0
            v0, v1, v2 = s[v], s[v + 1], s[v + 2]
            vn = (v0 * c0 + v2 * c2) + v1 * c1
            u0, u1, u2 = v0 - vn * c0, v1 - vn * c1, v2 - vn * c2
            vt = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2) * speed
            tangential_speed[o, c] = vt
            depth = -s[cd + 1]
            if touching:
                pen = depth if (depth >= 0.0 or math.isnan(depth)) else 0.0  # np.maximum
            else:
                pen = 0.0
            pen_m = pen * length
            penetration[o, c] = pen_m
            normal_force[o, c] = fn * force_n
            tangential_force[o, c] = ft * force_n
            t = state[o, c, 0] * time_u
            time_s[o, c] = t
            fd = (s[sp] + s[pu]) * force_n
            drive_force[o, c] = fd
            px, py, pz = s[p] * length, s[p + 1] * length, s[p + 2] * length
            position[o, c, 0], position[o, c, 1], position[o, c, 2] = px, py, pz
            w0, w1, w2 = v0 * speed, v1 * speed, v2 * speed
            velocity[o, c, 0], velocity[o, c, 1], velocity[o, c, 2] = w0, w1, w2
            if touching:
                normal[o, c, 0], normal[o, c, 1], normal[o, c, 2] = n0, n1, n2
                contact_point[o, c, 0] = s[cd + 2] * length
                contact_point[o, c, 1] = s[cd + 3] * length
                contact_point[o, c, 2] = s[cd + 4] * length
            else:
                normal[o, c, 0] = normal[o, c, 1] = normal[o, c, 2] = np.nan
                contact_point[o, c, 0] = contact_point[o, c, 1] = contact_point[o, c, 2] = np.nan
            carriage_x[o, c] = carriage[o, c] * length if spring[r] else np.nan
            slips = vt > slip_speed
            moving[o, c] = slips

            if marks[r, 1] < 0 and not (abs(t - dt * float(first + i + 1)) <= 0.5 * dt):
                marks[r, 1] = i
            if marks[r, 2] < 0 and not ((w0 * w0 + w1 * w1) + w2 * w2 <= speed_limit2[r]):
                marks[r, 2] = i
            if marks[r, 3] < 0 and pz < zmin:
                marks[r, 3] = i
            if marks[r, 4] < 0 and pz > ztop:
                marks[r, 4] = i
            if marks[r, 5] < 0 and pen_m > pen_tol:
                marks[r, 5] = i
            if marks[r, 6] < 0 and (
                (px < xmin + mg) or (px > xmax - mg) or (py < ymin + mg) or (py > ymax - mg)
            ):
                marks[r, 6] = i
            if marks[r, 7] < 0 and fd >= cap and not slips:
                marks[r, 7] = i
            if marks[r, 9] < 0 and not (abs(fd) <= force_limit[r]):
                marks[r, 9] = i

            held = False
            if touching and not slips:  # the lock rule: engagement.kappa_of_normal's region
                if n2 > 0:
                    fx, fy = -n0 / n2, -n1 / n2
                    held = ((1.0 + fy * fy) - m2 * fx * fx) < tol and fx > 0
                else:
                    held = n0 < 0
            if held:
                if not streak:
                    streak, base = True, fd
                if marks[r, 8] < 0 and fd - base >= rise:
                    marks[r, 8] = i
            else:
                streak = False
        held_out[r] = base if streak else np.nan

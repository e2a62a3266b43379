"""The rig's model: hfield geometry against the surface and MuJoCo's facets, placement, export,
surface swaps."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from sim_rigs import R_TIP, START, asymmetric_surface, deepest_contacts, plane_rig

from spine_mj.sim import Rig, StaticProbe, TipParams
from spine_mj.surfaces import GridSurface, TriangulatedSurface, from_hfield, inclined_plane, single_gaussian


def test_hfield_orientation_extent_and_scale_match_the_surface():
    surf = asymmetric_surface()
    rig = Rig(surf, tip=TipParams(tip_radius_m=1e-3))
    s = rig.length_scale_m
    tri = TriangulatedSurface.from_grid(from_hfield(rig.hfield))
    chord = 0.05**2 / 8 * 2.3 * s  # spacing^2 max|f''| / 8, in metres
    rng = np.random.default_rng(0)
    for x0, y0 in rng.uniform(-2.5, 2.5, (12, 2)):
        q = rig.place(x0, y0)
        contacts = deepest_contacts(rig, q)
        q = q * rig.units.length_m
        assert contacts, (x0, y0)
        for p, n in contacts:
            # the contact lies on the surface (in metres) and faces the smooth normal
            assert p[2] == pytest.approx(s * surf.height(p[0] / s, p[1] / s), abs=chord)
            assert p[2] == pytest.approx(s * tri.height(p[0] / s, p[1] / s), abs=1e-9)
            fx, fy = surf.gradient(p[0] / s, p[1] / s)
            ns = np.array([-fx, -fy, 1.0]) / math.hypot(1, math.hypot(fx, fy))
            assert math.degrees(math.acos(min(1.0, float(n @ ns)))) < 4.0
        # the sphere centre sits one radius from its contact
        assert np.linalg.norm(q - contacts[0][0]) == pytest.approx(rig.tip.tip_radius_m, rel=1e-3)


def _alt_normal(grid, x, y):
    """Facet normal with the *other* diagonal (x_max, y_min)-(x_min, y_max): must not match."""
    dx, dy = grid.spacing
    i = int((x - grid.x[0]) // dx)
    j = int((y - grid.y[0]) // dy)
    s, t = (x - grid.x[i]) / dx, (y - grid.y[j]) / dy
    h = grid.heights
    if s + t <= 1:
        fx, fy = (h[j, i + 1] - h[j, i]) / dx, (h[j + 1, i] - h[j, i]) / dy
    else:
        fx, fy = (h[j + 1, i + 1] - h[j + 1, i]) / dx, (h[j + 1, i + 1] - h[j, i + 1]) / dy
    n = np.array([-fx, -fy, 1.0])
    return n / np.linalg.norm(n)


def test_triangulated_surface_matches_mujoco_facets():
    rng = np.random.default_rng(1)
    x = np.linspace(-0.02, 0.02, 9)
    grid = GridSurface(heights=rng.uniform(0, 0.004, (9, 9)), x=x, y=x.copy(), unit="m")
    rig = Rig(grid, tip=TipParams(tip_radius_m=3e-3))
    tri = TriangulatedSurface.from_grid(from_hfield(rig.hfield, unit="m"))
    n_facet, n_alt_mismatch = 0, 0
    for x0, y0 in rng.uniform(-0.015, 0.015, (30, 2)):
        contacts = deepest_contacts(rig, rig.place(x0, y0))
        for p, _n in contacts:
            assert p[2] == pytest.approx(float(tri.height(p[0], p[1])), abs=1e-9)
        if len(contacts) == 1:  # inside a facet: the engine's normal is the facet normal
            p, n = contacts[0]
            fx, fy = tri.gradient(p[0], p[1])
            nt = np.array([-fx, -fy, 1.0]) / math.hypot(1, math.hypot(fx, fy))
            np.testing.assert_allclose(n, nt, atol=1e-6)
            n_facet += 1
            n_alt_mismatch += not np.allclose(n, _alt_normal(grid, p[0], p[1]), atol=1e-3)
    assert n_facet >= 10
    assert n_alt_mismatch >= 3


def test_contact_surface_is_where_the_engine_rests_the_tip_and_its_normal():
    """The rig's contact surface against MuJoCo: a tip placed by the engine's own distance
    sits at its height (plus the radius, less the soft contact's rest depth) and, where one
    contact holds it, that contact's normal gives the contact surface's slopes."""
    rng = np.random.default_rng(3)
    x = np.linspace(-0.02, 0.02, 11)
    h = rng.uniform(0, 0.004, (11, 11))
    h[4:6, :] += 0.008  # a steep wall, as grit has
    rig = Rig(GridSurface(heights=h, x=x, y=x.copy(), unit="m"), tip=TipParams(tip_radius_m=3e-3))
    contact = rig.contact_surface()
    r = rig.tip.tip_radius_m
    single = 0
    for x0, y0 in rng.uniform(-0.012, 0.012, (40, 2)):
        q = rig.place(x0, y0) * rig.units.length_m
        f, fx, fy = contact.evaluate(x0, y0, order=1)
        assert q[2] == pytest.approx(float(f) + r, abs=2e-4 * r)
        contacts = deepest_contacts(rig, rig.place(x0, y0))
        if len(contacts) == 1:
            n = contacts[0][1]
            np.testing.assert_allclose([fx, fy], [-n[0] / n[2], -n[1] / n[2]], rtol=1e-4, atol=1e-5)
            single += 1
    assert single >= 10


def test_triangulated_surface_interpolates_nodes_and_is_linear_per_facet():
    x = np.array([0.0, 1.0, 2.0, 3.0])
    h = np.arange(16.0).reshape(4, 4) ** 1.5
    tri = TriangulatedSurface(heights=h, x=x, y=x.copy())
    np.testing.assert_allclose(tri.height(x[None, :], x[:, None]), h)
    # lower triangle of cell (0, 0): vertices (0,0), (1,0), (1,1)
    fx, fy = tri.gradient(0.7, 0.2)
    assert fx == pytest.approx(h[0, 1] - h[0, 0]) and fy == pytest.approx(h[1, 1] - h[0, 1])
    fx, fy = tri.gradient(0.2, 0.7)
    assert fx == pytest.approx(h[1, 1] - h[1, 0]) and fy == pytest.approx(h[1, 0] - h[0, 0])
    assert np.all(np.asarray(tri.hessian(0.3, 0.6)) == 0)
    assert np.isnan(tri.height(5.0, 0.0))


def test_placement_starts_at_rest_without_impact():
    rig = plane_rig(20.0)
    res = rig.run(StaticProbe(start_force_n=0.5 * rig.scales.preload_n), start=START)
    settle = slice(0, res.drive_start_index)
    # a start one step above the surface would fall to g dt = 5 mm/s
    assert np.abs(res.velocity_m_s[settle]).max() < 2e-5
    assert res.penetration_m[settle].max() < 0.01 * R_TIP


def test_export_xml_is_self_contained(tmp_path):
    rig = Rig(single_gaussian(), engine=None)
    path = rig.export_xml(tmp_path / "rig.xml")
    m = mujoco.MjModel.from_xml_path(str(path))
    assert m.nhfield == 1 and m.hfield_nrow[0] == rig.hfield.nrow
    np.testing.assert_allclose(m.hfield_data, rig.model.hfield_data, atol=2e-6)
    # the model is in engine units: time in tau = sqrt(m L_c / F_p)
    assert m.opt.timestep == pytest.approx(rig.engine.timestep_s / rig.units.time_s, rel=1e-15)
    assert m.opt.noslip_iterations == rig.engine.noslip_iterations


def test_set_surface_recompiles_in_place():
    rig = Rig(single_gaussian(sign=1), tip=TipParams(tip_radius_m=5e-4))
    z_peak = rig.place(0.0, 0.0)[2] * rig.units.length_m
    rig.set_surface(single_gaussian(sign=-1))
    assert rig.place(0.0, 0.0)[2] * rig.units.length_m < z_peak - 0.03


def test_fine_grid_is_coarsened_to_respect_the_contact_cap():
    """MuJoCo keeps <= 50 contacts per geom pair: the P600 grid (2.6 um) under a 25 um tip
    would lose the deepest ones, so the rig resamples the hfield to ~R/4 and records it."""
    from spine_mj.surfaces import sandpaper

    surf = sandpaper(grit="P600", size_m=0.3e-3, rng=1)
    rig = Rig(surf, tip=TipParams(tip_radius_m=25e-6))
    assert rig.scales.hfield_spacing_m >= 0.25 * 25e-6 * (1 - 1e-9)
    assert rig.scales.hfield_resolution == rig.hfield.ncol
    for start in [(0.0, 0.0), (-1e-4, 5e-5), (1e-4, -1e-4)]:
        z = rig.place(*start)[2] * rig.units.length_m
        assert surf.height(*start) < z < surf.heights.max() + 2 * 25e-6


def test_placement_on_a_grid_finer_than_the_contact_cap_rests_the_tip_at_its_rest_depth():
    """A tip over many more cells than MuJoCo's 50 contacts per geom pair (a 10 deg plane
    refined 4 times, about 16 cells a tip radius): the placement's probe must not lose
    the deepest facet among those inside its contact margin, or the tip starts sunk into
    the surface (sandpaper at hfield x 2 started 0.11 tip radii deep and ended as
    "penetration" on its first step)."""
    from spine_mj.sim import build_rig
    from spine_mj.sim.step_rule import rest_depth_m

    plane = inclined_plane(slope_deg=10.0, half_width=0.01, n=81)
    rig = build_rig(plane, mu=0.5, tip_radius_m=1e-3, hfield_resolution=81, hfield_refinement=4)
    r = rig.scales.tip_radius_m
    assert rig.scales.hfield_spacing_m < 0.07 * r  # the tip spans hundreds of facets
    rest = rest_depth_m(rig.engine, rig.scales)
    d = mujoco.MjData(rig.model)
    for x0, y0 in [(0.0, 0.0), (1.3e-3, -2.1e-3), (-2.7e-3, 1.9e-3)]:
        d.qpos[:] = rig.place(x0, y0)
        mujoco.mj_forward(rig.model, d)
        assert 0 < d.ncon < 50
        depth = -d.contact.dist[: d.ncon].min() * rig.units.length_m  # along the normal
        assert depth == pytest.approx(rest * math.cos(math.radians(10.0)), rel=1e-3)


def _y_strip() -> GridSurface:
    """A strip 4 wide and 60 long whose heights vary along y as much as along x: a tip
    started on its flank (y = 1) is carried sideways."""
    x, y = np.linspace(0.0, 60.0, 1201), np.linspace(0.0, 4.0, 81)
    heights = (
        0.3 * np.sin(1.3 * x)[None, :]
        + 0.4 * np.sin(2 * np.pi * y / 8)[:, None]
        + 0.2 * np.sin(0.7 * x)[None, :] * np.cos(2 * np.pi * y / 4)[:, None]
    )
    return GridSurface(heights=heights, x=x, y=y)


def test_line_holds_the_tip_on_its_start_line_of_a_y_varying_strip():
    """Free, the tip drifts across the strip (measured: 1 unit off its line, then off the
    strip); held on its line it keeps y0 to 1e-6 units while the drive carries it along x,
    and the setting is recorded with the run."""
    from spine_mj import sim

    surf, start = _y_strip(), (10.0, 1.0)
    paths = {}
    for line in (False, True):
        rig = sim.build_rig(surf, mu=0.5, line=line or None)
        drive = sim.build_drive(rig.scales, "spring", ie=1e-3, duration_s=1.5)
        run = rig.run(drive, start=start)
        paths[line] = run.table()[["position_x_m", "position_y_m"]].to_numpy() / rig.length_scale_m
        assert run.summary()["engine"]["line"] is line
    free, held = paths[False], paths[True]
    assert np.abs(free[:, 1] - start[1]).max() > 0.1
    assert np.abs(held[:, 1] - start[1]).max() < 1e-6
    assert held[-1, 0] - start[0] > 1.0


def test_line_is_refused_where_it_cannot_hold():
    from spine_mj import sim
    from spine_mj.errors import SpineInputError
    from spine_mj.sim import Layout

    surf = _y_strip()
    with pytest.raises(SpineInputError, match=r"only an implicit integrator steps .* got integrator rk4"):
        sim.build_rig(surf, mu=0.5, line=True, integrator="rk4")
    with pytest.raises(SpineInputError, match="line must be true or false, got 'yes'"):
        sim.build_rig(surf, mu=0.5, line="yes")
    with pytest.raises(SpineInputError, match="not an array's spines"):
        sim.ArrayRig(sim.build_rig(surf, mu=0.5, line=True), Layout())


def test_contacts_at_counts_one_per_overlapped_prism_with_the_planes_normal_inside_a_cell():
    """A tip resting on a tilted plane: inside a cell one contact with the plane's normal and
    the placement's rest depth; centred over a grid vertex, one per prism it overlaps
    (docs/physics.md §5: up to six), every normal within a few degrees of the plane's."""
    from spine_mj.surfaces import inclined_plane

    slope = 20.0
    rig = Rig(inclined_plane(slope_deg=slope, half_width=0.02, n=41), tip=TipParams(tip_radius_m=2e-3))
    plane_n = np.array([-math.tan(math.radians(slope)), 0.0, 1.0])
    plane_n /= np.linalg.norm(plane_n)
    spacing = 0.04 / 40
    r = rig.tip.tip_radius_m
    # the contact point lies r sin(slope) ahead of the centre in +x: put it mid-cell
    foot = np.array([0.3 * spacing, 0.6 * spacing])
    q = rig.place(*(foot - [r * math.sin(math.radians(slope)), 0.0])) * rig.units.length_m
    depths, normals = rig.contacts_at(q)
    assert len(depths) == 1
    np.testing.assert_allclose(normals[0], plane_n, atol=1e-6)
    assert 0 < depths[0] < 0.01 * r  # the soft contact's rest depth, well under 1 % of the tip
    # pressed deeper at a vertex, the tip overlaps the prisms around it
    q_v = rig.place(-r * math.sin(math.radians(slope)), 0.0) * rig.units.length_m - 2e-5 * plane_n
    depths_v, normals_v = rig.contacts_at(q_v)
    assert 2 <= len(depths_v) <= 6
    assert np.all(depths_v > 0)
    tilts = np.degrees(np.arccos(np.clip(normals_v @ plane_n, -1, 1)))
    assert tilts.min() < 1e-3 and tilts.max() < 10.0


@pytest.mark.parametrize(
    ("start", "margin", "fragment"),
    [
        (
            (-5.0, -1.0),
            0.0,
            r"lies on the edge of the surface's domain x in \[-5, 5\], y in \[-5, 5\]; start inside",
        ),
        ((1.0, 5.0), 0.05, r"on the edge of .*by more than 0.05: a run ends \(left_domain\)"),
        ((-4.99, -1.0), 0.05, r"\(-4.99, -1\) lies within 0.05 of the edge of the surface's domain"),
        ((-5.01, -1.0), 0.05, r"\(-5.01, -1\) lies outside the surface's domain x in \[-5, 5\]"),
        ((0.0, float("nan")), 0.0, r"\(0, nan\) lies outside"),
    ],
)
def test_a_start_a_run_would_end_at_once_is_refused_naming_it_and_the_domain(start, margin, fragment):
    """A start on the domain's edge ran and ended left_domain at once; within the run's
    margin (a tip radius) the same. Starts strictly inside by more than it pass."""
    from spine_mj.errors import SpineInputError
    from spine_mj.sim.model import check_starts_on

    surface = single_gaussian()  # bounds (-5, 5, -5, 5)
    with pytest.raises(SpineInputError, match=fragment):
        check_starts_on(surface, [(0.0, 0.0), start], margin)
    check_starts_on(surface, [(-4.9, -1.0), (4.94, 4.94)], 0.05)


def test_a_run_refuses_a_start_within_its_detection_margin_and_takes_one_beyond_it():
    from spine_mj.errors import SpineInputError
    from spine_mj.sim import Detection, SpringDrive

    rig = plane_rig(0.0)
    xmin = rig.surface.bounds[0]
    margin = 4 * rig.tip.tip_radius_m
    drive = SpringDrive(speed_m_s=1e-3, stiffness_n_m=100.0, duration_s=1e-3)
    start = (xmin + 2 * rig.tip.tip_radius_m / rig.length_scale_m, 0.0)
    with pytest.raises(SpineInputError, match="lies within"):
        rig.run(drive, start=start, detection=Detection(domain_margin_m=margin))
    assert rig.run(drive, start=start).end_reason.name != "LEFT_DOMAIN"  # the default margin: a tip radius

"""Surface objects and generators: closed forms, derivative accuracy, statistics, seeds."""

import math

import numpy as np
import pytest
from scipy import ndimage

from spine_mj import SpineInputError, roughness
from spine_mj.surfaces import (
    GRIT_PARTICLE_DIAMETER_M,
    BallOnFacets,
    GaussianSurface,
    GridSurface,
    TriangulatedSurface,
    fractal_fbm,
    from_hfield,
    random_gaussians,
    sandpaper,
    single_gaussian,
    to_hfield,
)

RNG = np.random.default_rng(12345)


# ------------------------------------------------------------------ single Gaussian


def test_single_gaussian_paper_normalization():
    peak = single_gaussian()
    assert peak.height(0, 0) == pytest.approx(10 * math.pi / (2 * math.pi * 1.5**2))
    assert peak.height(0, 0) == pytest.approx(2.2222, abs=1e-4)
    # steepest slope of A exp(-r^2/2s^2) is A/s * exp(-1/2) at r = s
    x = np.linspace(0, 5, 20001)
    slope = np.abs(peak.gradient(x, 0 * x)[0]).max()
    assert slope == pytest.approx(10 / (2 * 1.5**2) / 1.5 * math.exp(-0.5), rel=1e-6)
    assert slope == pytest.approx(0.8986, abs=1e-4)


def test_valley_is_mirror_of_peak():
    peak, valley = single_gaussian(sign=1), single_gaussian(sign=-1)
    x, y = RNG.uniform(-5, 5, (2, 100))
    for a, b in zip(peak.evaluate(x, y), valley.evaluate(x, y)):
        np.testing.assert_allclose(a, -b)


def test_gaussian_derivatives_match_finite_differences():
    surf = random_gaussians(n_peaks=20, anisotropic=True, rng=4)
    x, y = RNG.uniform(-8, 8, (2, 200))
    h = 1e-5
    _, fx, fy, fxx, fxy, fyy = surf.evaluate(x, y)
    np.testing.assert_allclose(fx, (surf.height(x + h, y) - surf.height(x - h, y)) / (2 * h), atol=1e-7)
    np.testing.assert_allclose(fy, (surf.height(x, y + h) - surf.height(x, y - h)) / (2 * h), atol=1e-7)
    gx_p, _ = surf.gradient(x + h, y)
    gx_m, _ = surf.gradient(x - h, y)
    _, gy_p = surf.gradient(x, y + h)
    _, gy_m = surf.gradient(x, y - h)
    gxy_p, _ = surf.gradient(x, y + h)
    gxy_m, _ = surf.gradient(x, y - h)
    np.testing.assert_allclose(fxx, (gx_p - gx_m) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(fyy, (gy_p - gy_m) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(fxy, (gxy_p - gxy_m) / (2 * h), atol=1e-6)


def test_evaluation_broadcasts_and_matches_separate_calls():
    surf = single_gaussian()
    x = np.linspace(-4, 4, 7)[None, :]
    y = np.linspace(-3, 3, 5)[:, None]
    f = surf.height(x, y)
    assert f.shape == (5, 7)
    fx, fy = surf.gradient(x, y)
    fxx, fxy, fyy = surf.hessian(x, y)
    both = surf.evaluate(x, y)
    for a, b in zip((f, fx, fy, fxx, fxy, fyy), both):
        np.testing.assert_array_equal(a, b)
    assert surf.height(1.0, 2.0).shape == ()


# ------------------------------------------------------------------ gridded surfaces


def _grid_errors(h):
    """Max interior errors (value, slope, curvature) of a gridded Gaussian at spacing h."""
    exact = single_gaussian(bounds=(-6, 6, -6, 6))
    n = round(12 / h) + 1
    grid = exact.sample(n)
    x, y = np.random.default_rng(0).uniform(-4, 4, (2, 3000))
    e = exact.evaluate(x, y)
    g = grid.evaluate(x, y)
    return (
        np.abs(e[0] - g[0]).max(),
        max(np.abs(e[1] - g[1]).max(), np.abs(e[2] - g[2]).max()),
        max(np.abs(e[k] - g[k]).max() for k in (3, 4, 5)),
    )


def test_grid_interpolant_accuracy_and_convergence_order():
    coarse, fine = _grid_errors(0.1), _grid_errors(0.05)
    assert coarse[0] < 2e-6 and coarse[1] < 5e-5 and coarse[2] < 2e-3
    orders = [math.log2(c / f) for c, f in zip(coarse, fine)]
    assert orders[0] > 3.5, orders  # O(h^4) heights
    assert orders[1] > 2.5, orders  # O(h^3) slopes
    assert orders[2] > 1.7, orders  # O(h^2) curvatures


def test_grid_interpolates_its_samples():
    surf = fractal_fbm(nx=32, hurst=0.6, rng=1, periodic=False)
    xx, yy = np.meshgrid(surf.x, surf.y)
    np.testing.assert_allclose(surf.height(xx, yy), surf.heights, atol=1e-12)


def test_fast_grid_evaluation_matches_scipy_reference():
    """The hand-written B-spline gather equals scipy.ndimage.map_coordinates."""
    surf = fractal_fbm(nx=48, ny=40, hurst=0.7, rng=2)
    sp = surf.spline
    u = RNG.uniform(0, 48, 400)
    v = RNG.uniform(0, 40, 400)
    ref = ndimage.map_coordinates(surf.heights, [v, u], order=3, mode="grid-wrap")
    np.testing.assert_allclose(surf.height(sp.x0 + u * sp.dx, sp.y0 + v * sp.dy), ref, atol=1e-12)

    flat = fractal_fbm(nx=30, hurst=0.7, rng=3, periodic=False)
    pad = 8
    padded = np.pad(flat.heights, pad, mode="reflect", reflect_type="odd")
    u = RNG.uniform(0, 29, 300)
    v = RNG.uniform(0, 29, 300)
    ref = ndimage.map_coordinates(padded, [v + pad, u + pad], order=3, mode="mirror")
    sp = flat.spline
    np.testing.assert_allclose(flat.height(sp.x0 + u * sp.dx, sp.y0 + v * sp.dy), ref, atol=1e-12)


def test_periodic_grid_repeats_and_nonperiodic_is_nan_outside():
    surf = fractal_fbm(nx=32, size=(8.0, 6.0), hurst=0.8, rng=5)
    x, y = RNG.uniform(-3, 3, (2, 50))
    lx, ly = 8.0, 6.0
    for a, b in zip(surf.evaluate(x, y), surf.evaluate(x + lx, y - 2 * ly)):
        np.testing.assert_allclose(a, b, atol=1e-10)
    flat = single_gaussian().sample(21)
    assert np.isnan(flat.height(5.5, 0.0))
    assert np.isfinite(flat.height(5.0, -5.0))
    assert not flat.contains(5.5, 0.0) and flat.contains(0.0, 0.0)


def test_resample_keeps_surface():
    exact = single_gaussian()
    grid = exact.sample(101)
    fine = grid.resample(0.05)
    assert fine.spacing == pytest.approx((0.05, 0.05))
    x, y = RNG.uniform(-4, 4, (2, 200))
    np.testing.assert_allclose(fine.height(x, y), exact.height(x, y), atol=1e-4)


# ------------------------------------------------------------------ random Gaussians


def test_random_gaussians_reproducible_and_distributed_as_documented():
    a = random_gaussians(rng=7)
    b = random_gaussians(rng=7)
    c = random_gaussians(rng=8)
    for name in ("amplitude", "center_x", "center_y", "sigma_x", "sigma_y"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert not np.array_equal(a.center_x, c.center_x)
    assert a.n_gaussians == 100
    assert np.all((a.sigma_x >= 0.5) & (a.sigma_x <= 1.5))
    np.testing.assert_array_equal(a.sigma_x, a.sigma_y)
    assert np.all((a.amplitude >= 0.5) & (a.amplitude <= 1.5))
    assert np.all((a.center_x >= -10) & (a.center_x <= 10))
    concave = random_gaussians(sign=-1, rng=7)
    np.testing.assert_array_equal(concave.amplitude, -a.amplitude)
    big = random_gaussians(n_peaks=4000, rng=1)
    assert big.amplitude.mean() == pytest.approx(1.0, abs=0.02)
    assert big.center_x.mean() == pytest.approx(0.0, abs=0.3)


def test_random_gaussians_without_overlap_respect_separation():
    s = random_gaussians(n_peaks=30, overlap=False, min_separation=1.5, rng=3)
    d = np.hypot(s.center_x[:, None] - s.center_x, s.center_y[:, None] - s.center_y)
    need = 1.5 * (s.sigma_x[:, None] + s.sigma_x[None, :])
    off = ~np.eye(30, dtype=bool)
    assert np.all(d[off] >= need[off] - 1e-12)
    with pytest.raises(SpineInputError, match="could not place peak"):
        random_gaussians(n_peaks=500, overlap=False, min_separation=3, rng=1)


# ------------------------------------------------------------------ fractal


def radial_psd_slope(surf: GridSurface) -> float:
    """Log-log slope of the package's radially averaged PSD over the middle of the band."""
    q, psd = roughness.radial_psd(surf)
    k = q / (2 * np.pi) * surf.spacing[0]  # cycles per sample
    band = (k > 2 / surf.shape[1]) & (k < 0.3)
    return np.polyfit(np.log(q[band]), np.log(psd[band]), 1)[0]


@pytest.mark.parametrize("hurst", [0.3, 0.5, 0.7, 0.9])
def test_fractal_psd_slope_matches_hurst(hurst):
    slopes = [radial_psd_slope(fractal_fbm(nx=256, hurst=hurst, rng=s)) for s in range(3)]
    assert np.mean(slopes) == pytest.approx(-(2 * hurst + 2), abs=0.1)


@pytest.mark.parametrize("hurst", [0.3, 0.6, 0.9])
def test_fractal_psd_slope_by_surfacetopography(hurst):
    """Independent estimator: SurfaceTopography's radially averaged PSD."""
    import SurfaceTopography as st

    slopes = []
    for seed in range(3):
        surf = fractal_fbm(nx=256, hurst=hurst, rng=seed)
        topo = st.Topography(surf.heights.T, (20.0, 20.0), periodic=True)
        q, c = topo.power_spectrum_from_area(nb_points_per_decade=8)
        ok = np.isfinite(c) & (q > 2 * np.pi * 4 / 20) & (q < 2 * np.pi * 0.3 / (20 / 256))
        slopes.append(np.polyfit(np.log(q[ok]), np.log(c[ok]), 1)[0])
    assert np.mean(slopes) == pytest.approx(-(2 * hurst + 2), abs=0.1)


def test_fractal_normalization_and_reproducibility():
    a = fractal_fbm(nx=64, ny=63, hurst=0.7, rms_height=2.5, rng=11)
    b = fractal_fbm(nx=64, ny=63, hurst=0.7, rms_height=2.5, rng=11)
    np.testing.assert_array_equal(a.heights, b.heights)
    assert a.shape == (63, 64)
    assert a.heights.std() == pytest.approx(2.5)
    assert a.heights.mean() == pytest.approx(0.0, abs=1e-12)
    s = fractal_fbm(nx=128, hurst=0.7, rms_slope=0.4, rng=1)
    # periodic: the rms of the Fourier derivative (which drops the Nyquist row and column)
    spec = np.fft.fft2(s.heights)
    k = 2j * np.pi * np.fft.fftfreq(128, s.spacing[0])
    gx = np.fft.ifft2(spec * k[None, :]).real
    gy = np.fft.ifft2(spec * k[:, None]).real
    assert np.sqrt(np.mean(gx**2 + gy**2)) == pytest.approx(0.4, rel=0.01)
    nonper = fractal_fbm(nx=64, hurst=0.7, rms_slope=0.4, periodic=False, rng=1)
    gy, gx = np.gradient(nonper.heights, nonper.spacing[1], nonper.spacing[0])
    assert np.sqrt(np.mean(gx**2 + gy**2)) == pytest.approx(0.4)
    assert not nonper.periodic


# ------------------------------------------------------------------ sandpaper


@pytest.mark.parametrize("grit", ["P36", "P60", "P600"])
def test_sandpaper_resolves_tip_and_particles(grit):
    d = GRIT_PARTICLE_DIAMETER_M[grit]
    size = 12 * d
    s = sandpaper(grit=grit, size_m=size, rng=2)
    assert s.unit == "m" and s.periodic
    dx = s.spacing[0]
    assert dx <= 25e-6 / 5 + 1e-12 and dx <= d / 10 + 1e-12
    assert s.heights.min() == 0.0
    assert s.heights.max() <= 0.7 * d * 1.8  # exposed part of the largest grains
    np.testing.assert_array_equal(s.heights, sandpaper(grit=grit, size_m=size, rng=2).heights)


def test_sandpaper_covered_fraction_follows_boolean_model():
    """Footprints of random discs cover 1 - exp(-sum of footprint areas / area)."""
    s = sandpaper(grit="P60", size_m=4e-3, coverage=0.6, rng=9)
    meta = s.metadata["params"]
    d = meta["particle_diameter_m"]
    e_lo, e_hi = meta["embed_range"]
    # footprint radius^2 = r^2 - zc^2 with zc = r(1 - 2e); E over e ~ U(e_lo, e_hi)
    e = np.linspace(e_lo, e_hi, 1001)
    mean_factor = np.mean(1 - (1 - 2 * e) ** 2)
    cv = meta["size_cv"]
    mean_r2 = (d / 2) ** 2 * (1 + cv**2)
    density = meta["n_particles"] / 4e-3**2
    expected = 1 - math.exp(-density * math.pi * mean_r2 * mean_factor)
    covered = np.mean(s.heights > 0)
    assert covered == pytest.approx(expected, abs=0.05)


def test_sandpaper_roughness_scales_with_grit():
    rms = {
        g: sandpaper(grit=g, size_m=10 * GRIT_PARTICLE_DIAMETER_M[g], rng=1).heights.std()
        for g in ("P36", "P600")
    }
    ratio = GRIT_PARTICLE_DIAMETER_M["P36"] / GRIT_PARTICLE_DIAMETER_M["P600"]
    assert rms["P36"] / rms["P600"] == pytest.approx(ratio, rel=0.3)


# ------------------------------------------------------------------ hfield


def _asymmetric_grid():
    x = np.linspace(-2.0, 3.0, 26)
    y = np.linspace(-1.0, 1.5, 11)
    xx, yy = np.meshgrid(x, y)
    h = 0.1 * xx - 0.05 * yy + 2.0 * np.exp(-((xx - 1.5) ** 2 + (yy - 0.8) ** 2))
    return GridSurface(heights=h, x=x, y=y)


def test_hfield_round_trip_and_layout():
    surf = _asymmetric_grid()
    hf = to_hfield(surf)
    assert hf.data.dtype == np.float32 and hf.data.shape == (11, 26)
    assert hf.data.min() == 0.0 and hf.data.max() == pytest.approx(1.0)
    rx, ry, elev, base = hf.size
    assert (rx, ry) == pytest.approx((2.5, 1.25))
    assert elev == pytest.approx(np.ptp(surf.heights)) and base > 0
    assert hf.pos == pytest.approx((0.5, 0.25, surf.heights.min()))
    # row 0 is the smallest y, column 0 the smallest x
    iy, ix = np.unravel_index(np.argmax(hf.data), hf.data.shape)
    assert surf.x[ix] > 1.0 and surf.y[iy] > 0.5
    back = from_hfield(hf)
    np.testing.assert_allclose(back.x, surf.x)
    np.testing.assert_allclose(back.y, surf.y)
    np.testing.assert_allclose(back.heights, surf.heights, atol=1e-6 * elev)


def test_hfield_of_analytic_and_flat_surfaces():
    hf = to_hfield(single_gaussian(), ncol=51, nrow=41)
    assert hf.data.shape == (41, 51)
    assert hf.data[20, 25] == pytest.approx(1.0)
    flat = GridSurface(heights=np.zeros((5, 5)), x=np.arange(5.0), y=np.arange(5.0))
    hf = to_hfield(flat)
    assert hf.size[2] > 0 and np.all(hf.data == 0)


# ------------------------------------------------------------------ bad input


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(heights=np.full((5, 5), np.nan)), "NaN or infinite"),
        (dict(heights=np.where(np.eye(5) > 0, np.inf, 0.0)), "NaN or infinite"),
        (dict(heights=np.zeros((3, 5)), y=np.arange(3.0)), "at least 4 points a side"),
        (dict(x=np.array([0.0, 1, 1, 2, 3])), "strictly increasing"),
        (dict(x=np.array([0.0, 1, 2, 4, 5])), "uniformly spaced"),
        (dict(heights=np.zeros(25)), "2-D"),
    ],
)
def test_grid_surface_rejects_bad_data(kwargs, match):
    base = dict(heights=np.zeros((5, 5)), x=np.arange(5.0), y=np.arange(5.0))
    base.update(kwargs)
    with pytest.raises(SpineInputError, match=match):
        GridSurface(**base)


@pytest.mark.parametrize(
    "func, kwargs, match",
    [
        (fractal_fbm, dict(hurst=1.0), r"hurst must lie in the open interval \(0, 1\)"),
        (fractal_fbm, dict(hurst=0.0), "hurst"),
        (fractal_fbm, dict(hurst=0.5, nx=3), "nx must be an integer >= 4"),
        (fractal_fbm, dict(rms_height=1, rms_slope=1), "not both"),
        (fractal_fbm, dict(periodic=3), "periodic must be true or false, got 3"),
        (fractal_fbm, dict(periodic="no"), "periodic must be true or false"),
        (random_gaussians, dict(n_peaks=0), "n_peaks must be an integer in 1..100000"),
        (random_gaussians, dict(n_peaks=10**8), "n_peaks must be an integer in 1..100000"),
        (random_gaussians, dict(n_peaks=-5), "n_peaks"),
        (random_gaussians, dict(sigma_range=(0.0, 1.0)), "widths"),
        (random_gaussians, dict(sigma_range=(-1.0, 1.0)), "widths"),
        (random_gaussians, dict(sign=0), "sign"),
        (single_gaussian, dict(sigma_x=0), "sigma_x must be a finite number > 0"),
        (sandpaper, dict(grit="P80"), "grit must be one of"),
        (sandpaper, dict(grit="P36", spacing_m=-1), "spacing_m"),
        (random_gaussians, dict(rng=-1), "rng"),
    ],
)
def test_generators_reject_nonsense(func, kwargs, match):
    with pytest.raises(SpineInputError, match=match):
        func(**kwargs)


def test_gaussian_surface_rejects_bad_widths():
    with pytest.raises(SpineInputError, match="sigma_y must be > 0"):
        GaussianSurface(
            amplitude=[1.0],
            center_x=[0.0],
            center_y=[0.0],
            sigma_x=[1.0],
            sigma_y=[0.0],
            bounds=(-1, 1, -1, 1),
        )
    with pytest.raises(SpineInputError, match="bounds"):
        GaussianSurface(
            amplitude=[1.0],
            center_x=[0.0],
            center_y=[0.0],
            sigma_x=[1.0],
            sigma_y=[1.0],
            bounds=(1, -1, -1, 1),
        )


# ------------------------------------------------------------------ a ball on facets


def test_ball_on_a_tilted_plane_rides_its_offset_plane():
    """Face contacts only: the centre rides the plane lifted by r sqrt(1 + a^2 + b^2), at the
    plane's slopes (closed form)."""
    x = np.linspace(0.0, 1.0, 11)
    a, b = 0.7, -0.3
    tri = TriangulatedSurface(heights=a * x[None, :] + b * x[:, None], x=x, y=x.copy())
    ball = BallOnFacets(tri, 0.05)
    px, py = RNG.uniform(0.2, 0.8, (2, 50))
    f, fx, fy = ball.evaluate(px, py, order=1)
    lift = 0.05 * math.sqrt(1 + a * a + b * b) - 0.05
    np.testing.assert_allclose(f, a * px + b * py + lift, atol=1e-12)
    np.testing.assert_allclose(fx, a, atol=1e-12)
    np.testing.assert_allclose(fy, b, atol=1e-12)


def test_ball_on_a_spike_rides_the_sphere_around_its_tip():
    """One raised node on flat ground: within the spike's reach the ball rests on its
    vertex (a sphere of radius r around it), slopes pointing away from it."""
    x = np.linspace(-1.0, 1.0, 21)
    h = np.zeros((21, 21))
    h[10, 10] = 1.0
    ball = BallOnFacets(TriangulatedSurface(heights=h, x=x, y=x.copy()), 0.3)
    d = np.array([0.0, 0.05, 0.1])
    f, fx, fy = ball.evaluate(d, 0.5 * d, order=1)
    rho = np.hypot(d, 0.5 * d)
    z = 1.0 + np.sqrt(0.09 - rho**2)  # the centre on the vertex's sphere
    np.testing.assert_allclose(f, z - 0.3, atol=1e-12)
    np.testing.assert_allclose(fx, -d / (z - 1.0), atol=1e-12)
    np.testing.assert_allclose(fy, -0.5 * d / (z - 1.0), atol=1e-12)


def test_ball_on_facets_against_brute_force_over_the_footprint():
    """Random facets with a steep wall: the exact contact is at least as high as the best of
    a fine grid of points under the ball (the slow, obvious reference) and within its
    resolution; the slopes agree where they are moderate."""
    x = np.linspace(0.0, 1.0, 21)
    h = RNG.normal(0.0, 0.05, (21, 21))
    h[8:10, :] += 0.3
    tri = TriangulatedSurface(heights=h, x=x, y=x.copy())
    r, n = 0.05, 401
    ball = BallOnFacets(tri, r)
    pts = RNG.uniform(0.2, 0.8, (25, 2))
    f, fx, fy = ball.evaluate(pts[:, 0], pts[:, 1], order=1)
    u = np.linspace(-r, r, n)
    for k, (cx, cy) in enumerate(pts):
        gx, gy = np.meshgrid(cx + u, cy + u)
        d2 = (gx - cx) ** 2 + (gy - cy) ** 2
        inside = d2 <= r * r
        base = tri.height(gx[inside], gy[inside])
        top = base + np.sqrt(r * r - d2[inside])
        i = int(np.argmax(top))
        assert -1e-12 <= f[k] + r - top[i] <= 10 * (2 * r / (n - 1))  # slope 10 x one sample
        slope = np.array([gx[inside][i] - cx, gy[inside][i] - cy]) / (top[i] - base[i])
        if np.hypot(*slope) < 2:
            np.testing.assert_allclose([fx[k], fy[k]], slope, atol=0.02)


@pytest.mark.parametrize("radius", [0.02, 0.05, 0.16])
def test_ball_on_facets_compiled_matches_the_numpy_reference(radius):
    """The compiled contact against the array reference, on rough facets with a wall, a flat
    patch (ties between features) and points past the edges (the ball sees only the facets
    inside; no contact at all gives -inf)."""
    x = np.linspace(0.0, 1.0, 26)
    y = np.linspace(-0.5, 0.5, 21)
    h = RNG.normal(0.0, 0.05, (21, 26))
    h[8:10, :] += 0.3
    h[:, :6] = 0.0
    tri = TriangulatedSurface(heights=h, x=x, y=y)
    px = np.concatenate([RNG.uniform(-0.1, 1.1, 300), [0.1, 0.12, 1.0, 2.0]])
    py = np.concatenate([RNG.uniform(-0.6, 0.6, 300), [0.0, -0.2, 0.5, 2.0]])
    fast = BallOnFacets(tri, radius).evaluate(px, py, order=1)
    slow = BallOnFacets(tri, radius, compiled=False).evaluate(px, py, order=1)
    for a, b in zip(fast, slow):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
    assert fast[0][-1] == -np.inf


def test_ball_on_facets_rejects_bad_input():
    x = np.linspace(0.0, 1.0, 5)
    tri = TriangulatedSurface(heights=np.zeros((5, 5)), x=x, y=x.copy())
    with pytest.raises(SpineInputError, match="radius"):
        BallOnFacets(tri, 0.0)
    with pytest.raises(SpineInputError, match="TriangulatedSurface"):
        BallOnFacets(single_gaussian(), 0.1)
    with pytest.raises(SpineInputError, match="Hessian"):
        BallOnFacets(tri, 0.1).hessian(0.5, 0.5)


def test_gaussian_sum_on_a_grid_equals_its_pointwise_values():
    """The separable grid path (x a row, y a column) against the pointwise sum, orders 0-2."""
    from spine_mj.surfaces import GaussianSurface

    k = 30
    surf = GaussianSurface(
        amplitude=RNG.normal(0.0, 1.0, k),
        center_x=RNG.uniform(-2, 2, k),
        center_y=RNG.uniform(-2, 2, k),
        sigma_x=RNG.uniform(0.2, 1.0, k),
        sigma_y=RNG.uniform(0.2, 1.0, k),
        bounds=(-2, 2, -2, 2),
    )
    x, y = np.linspace(-2, 2, 37), np.linspace(-2.5, 2, 23)
    grid = surf.evaluate(x[None, :], y[:, None], order=2)
    X, Y = np.meshgrid(x, y)
    points = surf.evaluate(X, Y, order=2)
    for a, b in zip(grid, points):
        assert a.shape == (23, 37)
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize(
    "key, value", [("overlap", float("nan")), ("overlap", 2), ("anisotropic", "no"), ("anisotropic", None)]
)
def test_random_gaussians_refuse_a_flag_that_is_not_a_boolean(key, value):
    with pytest.raises(SpineInputError, match=f"{key} must be true or false"):
        random_gaussians(n_peaks=3, rng=0, **{key: value})


def test_sweep_set_with_a_non_boolean_flag_is_refused_when_the_config_is_read():
    from spine_mj.sweep import parse_config

    doc = {
        "surfaces": [{"preset": "paper-random-convex", "set": {"anisotropic": "no"}}],
        "starts": {"points": [[0.1, 0.5]]},
        "grid": {"mu": 0.5},
    }
    with pytest.raises(SpineInputError, match="anisotropic must be true or false"):
        parse_config(doc)


def test_gaussian_sums_in_byte_budget_blocks_equal_one_pass(monkeypatch):
    """A Gaussian surface evaluates points x Gaussians in blocks within BLOCK_BYTES (at
    MAX_PEAKS Gaussians one 32768-point chunk held 26 GB per temporary); whatever the
    blocks, on a tensor grid and pointwise, the sums are the one-pass ones."""
    from spine_mj.surfaces import types

    surf = random_gaussians(n_peaks=300, rng=1)
    x = np.linspace(*surf.bounds[:2], 57)
    y = np.linspace(*surf.bounds[2:], 43)
    xx, yy = np.meshgrid(x, y)
    whole = surf.evaluate(x[None, :], y[:, None], order=2)
    # blocks of 5 points, and of 15 Gaussians on the grid
    monkeypatch.setattr(types, "BLOCK_BYTES", 8 * 8 * 300 * 5)
    assert surf._points_per_chunk() == 5
    for got in (surf.evaluate(x[None, :], y[:, None], order=2), surf.evaluate(xx, yy, order=2)):
        for a, b in zip(got, whole, strict=True):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)

"""Concavity / convexity of self-lock points (paper §3.4.2-3.4.3, Eqs. 6-11).

Two criteria at a point with slopes ``(f_x, f_y)`` and Hessian ``H_s`` (Eq. 7):

* sectional (Eq. 6): the contour through the point, ``x = g(y)`` with ``f(g(y), y) =
  const``, has ``d2x/dy2 = -(f_xx f_y^2 - 2 f_xy f_x f_y + f_yy f_x^2) / f_x^3``;
  ``> 0`` is a convex self-lock, ``< 0`` a concave one;
* Hessian (Eqs. 8-10): ``det H_s < 0`` saddle, ``det H_s > 0`` and ``f_xx > 0`` concave,
  ``det H_s > 0`` and ``f_xx < 0`` convex.

Eq. 11 ties them: the numerator of Eq. 6 is ``v^T H_s v`` with ``v = (f_y, -f_x)``.
"""

from __future__ import annotations

import numpy as np

from spine_mj.errors import SpineInputError

__all__ = [
    "CONCAVE",
    "CONVEX",
    "FLAT",
    "HESSIAN_NAMES",
    "SADDLE",
    "SECTIONAL_NAMES",
    "hessian_class",
    "section_curvature",
    "sectional_class",
]

#: Class codes shared by both methods; SADDLE only from the Hessian method, FLAT where the
#: criterion is exactly zero (or undefined, f_x = 0, for the sectional method).
FLAT = 0
CONCAVE = 1
CONVEX = 2
SADDLE = 3
SECTIONAL_NAMES = {FLAT: "undetermined", CONCAVE: "concave", CONVEX: "convex"}
HESSIAN_NAMES = {FLAT: "undetermined", CONCAVE: "concave", CONVEX: "convex", SADDLE: "saddle"}


def _arrays(*args):
    try:
        return np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in args))
    except ValueError as exc:
        raise SpineInputError(f"derivative arrays must broadcast together: {exc}") from None


def section_curvature(fx, fy, fxx, fxy, fyy) -> np.ndarray:
    """``d2x/dy2`` of the contour section through each point (paper Eq. 6).

    Parameters
    ----------
    fx, fy, fxx, fxy, fyy : array_like, broadcast to shape S
        First and second derivatives of the surface (e.g. ``Surface.evaluate``).

    Returns
    -------
    ndarray, shape S
        ``-(f_xx f_y^2 - 2 f_xy f_x f_y + f_yy f_x^2) / f_x^3`` (1 / length); NaN where
        ``f_x = 0`` (the implicit function theorem does not apply).
    """
    fx, fy, fxx, fxy, fyy = _arrays(fx, fy, fxx, fxy, fyy)
    num = fxx * fy * fy - 2.0 * fxy * fx * fy + fyy * fx * fx
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(fx != 0, -num / np.where(fx != 0, fx, 1.0) ** 3, np.nan)


def sectional_class(fx, fy, fxx, fxy, fyy) -> np.ndarray:
    """Sectional criterion (Eq. 6): the curvature of the section along the drive.

    CONCAVE where ``d2x/dy2 < 0``, CONVEX where ``> 0``, FLAT where zero or undefined.

    Parameters
    ----------
    fx, fy : array_like
        Slopes of the height (dimensionless).
    fxx, fxy, fyy : array_like
        Second derivatives of the height (1 / length); all five broadcast together.

    Returns
    -------
    ndarray of int8
        The class codes, of the broadcast shape.
    """
    c = section_curvature(fx, fy, fxx, fxy, fyy)
    return np.where(c < 0, CONCAVE, np.where(c > 0, CONVEX, FLAT)).astype(np.int8)


def hessian_class(fxx, fxy, fyy) -> np.ndarray:
    """Hessian criterion (Eqs. 8-10) of the surface's curvature at points.

    SADDLE where ``det < 0``, CONCAVE where ``det > 0`` and ``f_xx > 0``, CONVEX where
    ``det > 0`` and ``f_xx < 0``, FLAT otherwise (``det = f_xx f_yy - f_xy^2``).

    Parameters
    ----------
    fxx, fxy, fyy : array_like
        Second derivatives of the height (1 / length), broadcast together.

    Returns
    -------
    ndarray of int8
        The class codes, of the broadcast shape.
    """
    fxx, fxy, fyy = _arrays(fxx, fxy, fyy)
    det = fxx * fyy - fxy * fxy
    return np.where(
        det < 0,
        SADDLE,
        np.where((det > 0) & (fxx > 0), CONCAVE, np.where((det > 0) & (fxx < 0), CONVEX, FLAT)),
    ).astype(np.int8)


def classify_points(surface, x, y) -> tuple[np.ndarray, np.ndarray]:
    """Sectional and Hessian classes of points ``(x, y)`` on ``surface``.

    Parameters
    ----------
    surface : Surface
        Any surface (its exact or interpolated second derivatives are used).
    x, y : array_like
        Points inside ``surface.bounds``, broadcast together to shape ``S``.

    Returns
    -------
    sectional, hessian : ndarray of int8, shape S
        :func:`sectional_class` (Eq. 6) and :func:`hessian_class` (Eqs. 8-10) codes.
    """
    _, fx, fy, fxx, fxy, fyy = surface.evaluate(x, y, order=2)
    return sectional_class(fx, fy, fxx, fxy, fyy), hessian_class(fxx, fxy, fyy)


__all__ += ["classify_points"]

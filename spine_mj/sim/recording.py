"""What a run records, step by step: the per-step columns read from MuJoCo's sensors.

:class:`Recording` holds the arrays of one run (or, with a leading run axis, of a group of
runs of equal length) under the names :class:`~spine_mj.sim.RunResult` gives them, plus
the tangential speed the stick/slip states come from. It is built once per group from the
rollout's state and sensordata (:meth:`Recording.from_sensors`) and passed whole to the
event detection and to the result, instead of a dozen loose arrays. MuJoCo's numbers are
in engine units (:class:`~spine_mj.sim.scales.EngineUnits`); :meth:`Recording.from_sensors`
is the one place they become SI.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from spine_mj.sim.scales import EngineUnits

#: The rig's sensors (``models/spine_rig.xml``): ``contact_net`` is the net force of all the
#: tip's contacts, ``contact_deepest`` the deepest contact, ``contact_normal`` the sum of the
#: normal forces of all the tip's contacts (MuJoCo's touch sensor).
SENSOR_NAMES = (
    "tip_pos",
    "tip_vel",
    "contact_net",
    "contact_deepest",
    "spring_force",
    "push_force",
    "contact_normal",
)


@dataclass(frozen=True, eq=False)
class RunColumns:
    """The per-step arrays every run records, declared once: the fields that
    :class:`Recording` and :class:`~spine_mj.sim.RunResult` share (documented there)."""

    time_s: np.ndarray
    position_m: np.ndarray
    velocity_m_s: np.ndarray
    contact: np.ndarray
    normal: np.ndarray
    contact_point_m: np.ndarray
    penetration_m: np.ndarray
    normal_force_n: np.ndarray
    tangential_force_n: np.ndarray
    drive_force_n: np.ndarray
    carriage_x_m: np.ndarray
    moving: np.ndarray


@dataclass(frozen=True)
class Recording(RunColumns):
    """Per-step arrays of a run ``(n, ...)`` or of a group of runs ``(g, n, ...)``.

    Attributes
    ----------
    time_s, position_m, velocity_m_s, contact, normal, contact_point_m, penetration_m,
    normal_force_n, tangential_force_n, drive_force_n, carriage_x_m, moving
        As in :class:`~spine_mj.sim.RunResult` (:class:`RunColumns`).
    tangential_speed_m_s
        Tip speed in the tangent plane of the deepest contact [m/s] (the full speed
        without contact).
    """

    tangential_speed_m_s: np.ndarray

    @classmethod
    def empty(cls, shape: tuple[int, ...]) -> Recording:
        """Uninitialised columns with leading shape ``shape`` (``(n,)`` or ``(g, n)``)."""
        return cls(**{k: np.empty(shape + tail, dtype) for k, (tail, dtype) in _LAYOUT.items()})

    @classmethod
    def from_sensors(
        cls,
        sensor_adr: dict[str, int],
        state: np.ndarray,
        sens: np.ndarray,
        *,
        units: EngineUnits,
        carriage_x: np.ndarray,
        move_speed_m_s: float,
        out: Recording | None = None,
    ) -> Recording:
        """The recording of a group in SI: ``state`` ``(g, n, nstate)``, ``sens`` ``(g, n,
        nsensordata)`` and the carriage ``carriage_x`` ``(g, n)`` in engine ``units``.

        The columns are computed for the whole group in one pass (the same arithmetic per
        row as one run at a time); a step slips when its tangential speed exceeds
        ``move_speed_m_s``. ``out``: columns of that shape (views into larger ones are
        fine) to write into and return, instead of new arrays.
        """
        rec = cls.empty(state.shape[:-1]) if out is None else out
        sensor_columns(sensor_adr, state, sens, units, rec)
        np.multiply(carriage_x, units.length_m, out=rec.carriage_x_m)
        np.greater(rec.tangential_speed_m_s, move_speed_m_s, out=rec.moving)
        return rec

    def run(self, r: int, rows: int | None = None) -> Recording:
        """Run ``r`` of a group, its first ``rows`` rows (all: None), as views of the group's columns."""
        return Recording(*[getattr(self, k)[r, :rows] for k in COLUMNS])  # fields in COLUMNS order

    def read_only(self) -> Recording:
        """The same columns as read-only views (slices of them are read-only too)."""

        def view(a):
            out = a.view()
            out.flags.writeable = False
            return out

        return Recording(**{k: view(getattr(self, k)) for k in COLUMNS})


#: The column names of a :class:`Recording`, in field order (the order the compiled
#: window kernel takes them in, :mod:`~spine_mj.sim._window_kernel`).
COLUMNS = tuple(f.name for f in dataclasses.fields(Recording))
#: The columns a :class:`~spine_mj.sim.RunResult` carries (the tangential speed stays behind).
RESULT_COLUMNS = tuple(f.name for f in dataclasses.fields(RunColumns))
#: Each column's trailing shape and dtype.
_LAYOUT = {
    k: ((3,) if k in ("position_m", "velocity_m_s", "normal", "contact_point_m") else (), float)
    for k in COLUMNS
}
_LAYOUT["contact"] = _LAYOUT["moving"] = ((), bool)


def sensor_columns(
    sensor_adr: dict[str, int], state: np.ndarray, sens: np.ndarray, units: EngineUnits, out: Recording
) -> None:
    """Write the per-step columns of steps ``state`` ``(..., nstate)`` and ``sens`` ``(...,
    nsensordata)`` (engine ``units``) into ``out`` in SI (all but the carriage and moving).

    The arithmetic runs on component arrays of the leading shape (numpy's loops over a
    length-3 axis cost more than the arithmetic), row by row the operations of a plain
    per-row evaluation; each column is computed in engine units and multiplied by its
    unit last.
    """
    a = sensor_adr
    cn, cd, v, p = a["contact_net"], a["contact_deepest"], a["tip_vel"], a["tip_pos"]
    length, force_n, speed = units.length_m, units.force_n, units.speed_m_s
    col = np.moveaxis(sens, -1, 0).copy()  # one pass over the rows; then every sensor is contiguous
    contact = np.greater(col[cd], 0, out=out.contact)
    no_contact = ~contact
    flip = col[cd + 7] < 0  # the sensor's normal, turned to point out of the surface
    normal = [np.where(flip, np.negative(col[cd + 5 + j]), col[cd + 5 + j]) for j in range(3)]
    nn = [np.where(contact, c, 0.0) for c in normal]  # the normal, 0 without contact
    if not all(np.isfinite(c).all() for c in nn):  # engine trouble: keep the arithmetic finite
        nn = [np.nan_to_num(c) for c in nn]
    force = [np.negative(col[cn + 1 + j]) for j in range(3)]  # the sensor: the tip's force on the surface
    # the normal load is the sum over the contacts, not the net force along one normal: in a
    # wedge that projection is smaller, even negative (-16 F_p held at a P60 grit's crease)
    fn = np.where(contact, col[a["contact_normal"]], 0.0)
    along = _dot3(nn, force)  # 0 without contact (nn = 0)
    ft = np.where(contact, _norm3([force[j] - along * nn[j] for j in range(3)]), 0.0)
    vel = [col[v + j] for j in range(3)]
    vn = _dot3(vel, nn)
    np.multiply(_norm3([vel[j] - vn * nn[j] for j in range(3)]), speed, out=out.tangential_speed_m_s)
    pen = np.where(contact, np.maximum(np.negative(col[cd + 1]), 0.0), 0.0)
    np.multiply(pen, length, out=out.penetration_m)
    np.multiply(fn, force_n, out=out.normal_force_n)
    np.multiply(ft, force_n, out=out.tangential_force_n)
    np.multiply(state[..., 0], units.time_s, out=out.time_s)
    np.add(col[a["spring_force"]], col[a["push_force"]], out=out.drive_force_n)
    np.multiply(out.drive_force_n, force_n, out=out.drive_force_n)
    for j in range(3):
        np.multiply(col[p + j], length, out=out.position_m[..., j])
        np.multiply(vel[j], speed, out=out.velocity_m_s[..., j])
        np.copyto(out.normal[..., j], normal[j])
        np.copyto(out.normal[..., j], np.nan, where=no_contact)
        np.multiply(col[cd + 2 + j], length, out=out.contact_point_m[..., j])
        np.copyto(out.contact_point_m[..., j], np.nan, where=no_contact)


def _dot3(u: list[np.ndarray], v: list[np.ndarray]) -> np.ndarray:
    """Row-wise dot product of two vectors given by components, summed as numpy's einsum
    ``"ij,ij->i"`` sums three terms: ``(u0 v0 + u2 v2) + u1 v1``."""
    return (u[0] * v[0] + u[2] * v[2]) + u[1] * v[1]


def _norm3(c: list[np.ndarray]) -> np.ndarray:
    """Row-wise length of a vector given by components, summed as ``np.linalg.norm(v,
    axis=1)`` of ``(N, 3)`` rows sums (fewer than 8 terms, in order): ``(x^2 + y^2) + z^2``."""
    x, y, z = c
    return np.sqrt(x * x + y * y + z * z)

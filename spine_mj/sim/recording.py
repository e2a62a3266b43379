"""What a run records, step by step: the per-step columns read from MuJoCo's sensors.

:class:`Recording` holds the arrays of one run (or, with a leading run axis, of a group of
runs of equal length) under the names :class:`~spine_mj.sim.RunResult` gives them, plus
the tangential speed the stick/slip states come from. It is built once per group from the
rollout's state and sensordata (:meth:`Recording.from_sensors`) and passed whole to the
event detection and to the result, instead of a dozen loose arrays. MuJoCo's numbers are
in engine units (:class:`~spine_mj.sim.params.EngineUnits`); :meth:`Recording.from_sensors`
is the one place they become SI.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from spine_mj.sim.params import EngineUnits

SENSOR_NAMES = ("tip_pos", "tip_vel", "contact_net", "contact_deepest", "spring_force", "push_force")


@dataclass(frozen=True)
class Recording:
    """Per-step arrays of a run ``(n, ...)`` or of a group of runs ``(g, n, ...)``.

    Attributes
    ----------
    time_s, position_m, velocity_m_s, contact, normal, contact_point_m, penetration_m,
    normal_force_n, tangential_force_n, drive_force_n, carriage_x_m, slipping
        As in :class:`~spine_mj.sim.RunResult`.
    tangential_speed_m_s
        Tip speed in the tangent plane of the deepest contact [m/s] (the full speed
        without contact).
    """

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
    tangential_speed_m_s: np.ndarray
    carriage_x_m: np.ndarray
    slipping: np.ndarray

    @classmethod
    def from_sensors(
        cls,
        sensor_adr: dict[str, int],
        state: np.ndarray,
        sens: np.ndarray,
        *,
        units: EngineUnits,
        carriage_x: np.ndarray,
        slip_speed_m_s: float,
    ) -> Recording:
        """The recording of a group in SI: ``state`` ``(g, n, nstate)``, ``sens`` ``(g, n,
        nsensordata)`` and the carriage ``carriage_x`` ``(g, n)`` in engine ``units``.

        The columns are computed for the whole group in one pass (the same arithmetic per
        row as one run at a time); a step slips when its tangential speed exceeds
        ``slip_speed_m_s``.
        """
        g, n = state.shape[:2]
        cols = sensor_columns(sensor_adr, state.reshape(g * n, -1), sens.reshape(g * n, -1))
        cols = {k: to_si(k, c, units).reshape(g, n, *c.shape[1:]) for k, c in cols.items()}
        slipping = cols["tangential_speed_m_s"] > slip_speed_m_s
        return cls(**cols, carriage_x_m=carriage_x * units.length_m, slipping=slipping)

    def run(self, r: int, rows: int | None = None) -> Recording:
        """Run ``r`` of a group, its first ``rows`` rows (all: None), as views of the group's columns."""
        return Recording(**{k: getattr(self, k)[r, :rows] for k in COLUMNS})

    def cut(self, end: int) -> Recording:
        """Steps ``0..end`` of a run, as read-only views of its columns."""

        def view(a):
            out = a[: end + 1]  # a view of the group's column (C-contiguous rows), read-only
            out.flags.writeable = False
            return out

        return Recording(**{k: view(getattr(self, k)) for k in COLUMNS})


#: The column names of a :class:`Recording`, in field order.
COLUMNS = tuple(f.name for f in dataclasses.fields(Recording))


def sensor_columns(sensor_adr: dict[str, int], state: np.ndarray, sens: np.ndarray) -> dict[str, np.ndarray]:
    """Per-step columns of ``N`` steps (``state`` ``(N, nstate)``, ``sens`` ``(N, nsensordata)``).

    Every column is a fresh C-contiguous array: the strided sensor slices are copied
    once, so the arithmetic reads contiguous memory (the row-wise operations, einsum
    and norm included, are those of a plain per-row evaluation: same results).
    """
    a = sensor_adr
    cn, cd = a["contact_net"], a["contact_deepest"]
    t = state[:, 0].copy()
    pos = sens[:, a["tip_pos"] : a["tip_pos"] + 3].copy()
    vel = sens[:, a["tip_vel"] : a["tip_vel"] + 3].copy()
    contact = sens[:, cd] > 0
    no_contact = ~contact[:, None]
    force = np.negative(sens[:, cn + 1 : cn + 4])  # the sensor reports the tip's force on the surface
    normal = sens[:, cd + 5 : cd + 8].copy()
    np.negative(normal, out=normal, where=normal[:, 2:3] < 0)  # point out of the surface
    np.copyto(normal, np.nan, where=no_contact)
    point = sens[:, cd + 2 : cd + 5].copy()
    np.copyto(point, np.nan, where=no_contact)
    pen = np.where(contact, np.maximum(-sens[:, cd + 1], 0.0), 0.0)
    nn = np.nan_to_num(normal)
    fn = np.where(contact, np.einsum("ij,ij->i", nn, force), 0.0)
    ft = np.where(contact, _norm3(force - fn[:, None] * nn), 0.0)
    drive_f = sens[:, a["spring_force"]] + sens[:, a["push_force"]]
    vt = vel - np.einsum("ij,ij->i", vel, nn)[:, None] * nn
    return {
        "time_s": t,
        "position_m": pos,
        "velocity_m_s": vel,
        "contact": contact,
        "normal": normal,
        "contact_point_m": point,
        "penetration_m": pen,
        "normal_force_n": fn,
        "tangential_force_n": ft,
        "drive_force_n": drive_f,
        "tangential_speed_m_s": _norm3(vt),
    }


def to_si(name: str, column: np.ndarray, units: EngineUnits) -> np.ndarray:
    """A column of :func:`sensor_columns` converted from engine units to SI, by its name's unit."""
    unit = {
        "_s": units.time_s,
        "_m": units.length_m,
        "_m_s": units.speed_m_s,
        "_n": units.force_n,
    }
    for suffix in ("_m_s", "_s", "_m", "_n"):
        if name.endswith(suffix):
            return column * unit[suffix] if column.dtype.kind == "f" else column
    return column


def _norm3(v: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(v, axis=1)`` of ``(N, 3)`` rows, bit for bit (numpy sums fewer than 8
    terms in order: ``(x^2 + y^2) + z^2``), without the slow reduction over a short axis."""
    x, y, z = v[:, 0], v[:, 1], v[:, 2]
    return np.sqrt(x * x + y * y + z * z)

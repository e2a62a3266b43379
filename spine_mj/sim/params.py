"""The rig's parameters and their rules, in one import.

Three modules, one concern each, every name re-exported here (the import path of the
rig's parameters since the start):

* :mod:`spine_mj.sim.records`: the parameter records (frozen, validated on construction):
  :class:`TipParams` (the spine tip), :class:`EngineSettings` (MuJoCo settings, recorded
  with every run), the enums they use and :class:`EndReason`.
* :mod:`spine_mj.sim.scales`: :class:`Scales`, the problem's scales from a surface and a
  tip (length scale, ``L_c``, ``l_s``, default tip radius, hfield spacing and coarsening,
  fall height), :class:`EngineUnits` the units MuJoCo works in, and the scaling rule.
* :mod:`spine_mj.sim.step_rule`: :func:`default_engine`, the engine settings from the
  scales (rule in :mod:`spine_mj.sim`'s docstring), and the bounds a user's settings meet.

The surface's lengths the scales use (:func:`characteristic_length`,
:func:`slope_correlation_length`) are re-exported from :mod:`spine_mj.roughness`. Nothing
here needs MuJoCo.
"""

from spine_mj.roughness import characteristic_length, slope_correlation_length
from spine_mj.sim.records import (
    MAX_PRELOAD_ACCELERATION_M_S2,
    PHYSICAL_MASS_KG,
    Cone,
    EndReason,
    EngineSettings,
    Integrator,
    TipParams,
    check_optional,
)
from spine_mj.sim.scales import (
    DEFAULT_LENGTH_SCALE_M,
    LENGTH_UNITS_M,
    MAX_HFIELD_SIDE,
    MAX_INERTIA_NUMBER,
    PHYSICAL_LENGTH_M,
    EngineUnits,
    Scales,
    check_inertia_number,
    check_physical_length,
    default_tip_radius,
    fall_height,
    hfield_of,
    hfield_spacing,
    surface_unit_m,
)
from spine_mj.sim.step_rule import (
    DEFAULT_STIFFNESS_NUMBER,
    MAX_DRIVE_ADVANCE_PER_STEP,
    MAX_SPRING_OMEGA_DT,
    MIN_TIMESTEP_TAU,
    SPRING_OMEGA_DT,
    EngineOverrides,
    check_drive_speed,
    check_engine_for,
    default_engine,
    penetration_tolerance_m,
    rest_depth_m,
    spring_omega_dt,
)

__all__ = [
    "DEFAULT_LENGTH_SCALE_M",
    "DEFAULT_STIFFNESS_NUMBER",
    "LENGTH_UNITS_M",
    "MAX_DRIVE_ADVANCE_PER_STEP",
    "MAX_HFIELD_SIDE",
    "MAX_INERTIA_NUMBER",
    "MAX_PRELOAD_ACCELERATION_M_S2",
    "MAX_SPRING_OMEGA_DT",
    "MIN_TIMESTEP_TAU",
    "PHYSICAL_LENGTH_M",
    "PHYSICAL_MASS_KG",
    "SPRING_OMEGA_DT",
    "Cone",
    "EndReason",
    "EngineOverrides",
    "EngineSettings",
    "EngineUnits",
    "Integrator",
    "Scales",
    "TipParams",
    "characteristic_length",
    "check_drive_speed",
    "check_engine_for",
    "check_inertia_number",
    "check_optional",
    "check_physical_length",
    "default_engine",
    "default_tip_radius",
    "fall_height",
    "hfield_of",
    "hfield_spacing",
    "penetration_tolerance_m",
    "rest_depth_m",
    "slope_correlation_length",
    "spring_omega_dt",
    "surface_unit_m",
]

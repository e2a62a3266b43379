"""Report text of the stick-slip study's K scan (:func:`spine_mj.validate.stick_slip.k_scan`):
slip events against K / K* on a corrugation, and where stick-slip gives way to sliding.
"""

from __future__ import annotations

from spine_mj.sim.motion import SLIP_SPEED_FACTOR
from spine_mj.validate.stick_slip import K_SCAN_SURFACE, SLIPS_PER_WAVE, StickSlipResult

__all__ = ["k_scan_section"]


def k_scan_section(stick: StickSlipResult, table, f) -> list[str]:
    """The K-scan paragraph and tables ([] without a scan); ``table`` and ``f`` are the
    report's formatters."""
    if not stick.k_scan:
        return []
    s, mu = K_SCAN_SURFACE
    lines = [
        f"**Slip events against K on a corrugation** (slope amplitude {s:g}, mu {mu:g}, K* = "
        f"{f(stick.k_star)} from the Prandtl-Tomlinson closed form). A slip is a stretch where the "
        f"tip outruns the carriage and reaches {SLIP_SPEED_FACTOR:g} V (docs/physics.md §6); steady "
        "sliding is no slip.",
        "",
        table(
            stick.k_scan,
            [
                "ie",
                "k_over_k_star",
                "slip_events",
                "events_per_wave",
                "onset_mean_fp",
                "stuck",
                "sliding",
                "slipping",
                "max_speed_v",
            ],
            [
                "I_e",
                "K / K*",
                "slips",
                "per wavelength",
                "mean onset (F_p)",
                "stuck",
                "sliding",
                "slipping",
                "max speed (V)",
            ],
        ),
        "",
        f"Where stick-slip (at least {SLIPS_PER_WAVE:g} slips per wavelength) gives way to steady "
        "sliding, against the prediction K*:",
        "",
        table(
            stick.transitions,
            ["ie", "k_low", "k_high", "over_k_star"],
            ["I_e", "last K with stick-slip", "first K sliding", "transition / K*"],
        ),
        "",
    ]
    return lines

"""The physical cause of a miss: why a run of the quasistatic-limit study disagrees with
its reference, read from its compare row (the miss reason of
:func:`spine_mj.theory.agreement.miss_reason`, how the engine ended, whether the reference
slid under gravity and how fast the tip went): a fall from a flank steeper than friction,
a wedge, the soft contact, a jump, or an ill-conditioned start.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FALL_IE_FACTOR", "MISS_CAUSES", "miss_cause"]

#: A peak speed this many times the drive's in inertia number (10 times in speed) is a
#: fall's or a jump's: a stable slide moves at most a few drive speeds (docs/physics.md §6).
FALL_IE_FACTOR = 100.0


#: The physical cause of each miss (:func:`miss_cause`), and what each means.
MISS_CAUSES = {
    "fall_landed": "the streamline missed where the tip fell, and the fall-landing reference "
    "(the fall replaced by the inertial tip on the run's spring until it lands: "
    "spine_mj.theory.fall_landing) agrees: explained by where a tip with mass lands",
    "ill_conditioned": "the reference's outcome flips within one hfield spacing of its path "
    "(miss reason separatrix): the start lies on a separatrix, no physics is missing",
    "fall": "the paths parted where the tip fell: the reference slides under gravity alone "
    "(a flank steeper than friction) or the tip's peak speed was a fall's (its inertia "
    f"number above {FALL_IE_FACTOR:g} times the drive's), where the quasistatic step does not say where "
    "a tip with mass lands, and the fall-landing reference (where it was traced) misses too",
    "inertia": "the paths parted by more than a facet without a fall (a jump of the spring)",
    "wedge": "MuJoCo held at the force cap without a single contact normal in the self-lock "
    "region: the tip wedged on several contacts where the reference moves on",
    "soft_contact": "MuJoCo held on a single contact normal where the reference moves on, or "
    "passed where the reference holds: the soft contact's tilted normals and creep",
    "reference_stalled": "the reference made no progress: nothing to compare",
}


def miss_cause(row) -> str:
    """The physical cause (a key of :data:`MISS_CAUSES`) of one run that disagrees with the
    streamline, from its compare row: its ``agree_landing`` (the fall-landing reference's
    verdict, where its reference falls), ``miss_reason``, ``end_detail``,
    ``reference_slide_fraction``, ``tip_peak_ie`` and ``inertia_number``."""
    if row.get("agree_landing") == 1:
        return "fall_landed"
    reason = row.get("miss_reason", "")
    if reason == "separatrix":
        return "ill_conditioned"
    if reason == "engine_held":
        return "wedge" if str(row.get("end_detail", "")).startswith("force cap") else "soft_contact"
    if reason == "engine_passed":
        return "soft_contact"
    if reason == "reference_stalled":
        return "reference_stalled"
    slid = float(row.get("reference_slide_fraction", 0.0) or 0.0) > 0
    peak, drive = float(row.get("tip_peak_ie", np.nan)), float(row.get("inertia_number", np.nan))
    fast = np.isfinite(peak) and np.isfinite(drive) and peak > FALL_IE_FACTOR * drive
    return "fall" if slid or fast else "inertia"

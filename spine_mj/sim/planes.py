"""Inclined planes, the surfaces with a closed-form answer for checking the rig: a surface
generator, kept in :mod:`spine_mj.surfaces.generators` and importable here as before."""

from spine_mj.surfaces.generators import inclined_plane

__all__ = ["inclined_plane"]

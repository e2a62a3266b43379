"""Surface recipes: small TOML presets in the repository's ``surfaces/`` folder (shipped
in the package as ``spine_mj._data.surfaces``, see :mod:`spine_mj.resources`).

A preset names a generator and its parameters::

    description = "The paper's single convex Gaussian peak (Figs. 3-4)"
    generator = "single_gaussian"

    [params]
    sign = 1
    k = 31.41592653589793

Other top-level tables (for example ``[engagement]`` with the friction coefficient the
analytic reproduction uses) travel with the preset in :attr:`Preset.extras`, so that
calibrated defaults live in the presets, not in code.

``SPINE_MJ_SURFACES`` overrides the folder searched for presets.
"""

from __future__ import annotations

import inspect
import math
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from spine_mj import examples, resources, surface_io, surfaces
from spine_mj.errors import SpineInputError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

__all__ = [
    "GENERATORS",
    "Preset",
    "SurfaceInfo",
    "calibrated_mu",
    "check_generator_params",
    "list_presets",
    "load_preset",
    "make_surface",
    "make_surface_file",
    "open_surface",
    "parse_override",
    "preset_descriptions",
    "preset_mu",
    "presets_dir",
    "resolve_mu",
    "surface_info",
]


def _measured(*, file: str, **options):

    path = Path(file)
    if not path.is_absolute():
        path = presets_dir() / path
    return surface_io.import_topography(path, **options)


#: Generator names usable in a preset, and the functions they call.
GENERATORS = {
    "single_gaussian": surfaces.single_gaussian,
    "corrugation": surfaces.corrugation,
    "abbm_track": surfaces.abbm_track,
    "inclined_plane": surfaces.inclined_plane,
    "random_gaussians": surfaces.random_gaussians,
    "fractal_fbm": surfaces.fractal_fbm,
    "sandpaper": surfaces.sandpaper,
    "measured": _measured,
}


def presets_dir() -> Path:
    """The folder holding the ``*.toml`` presets (``SPINE_MJ_SURFACES``, else the ones
    shipped with the package: :func:`spine_mj.resources.presets_dir`)."""
    env = os.environ.get("SPINE_MJ_SURFACES")
    return Path(env) if env else resources.presets_dir()


@dataclass(frozen=True)
class Preset:
    """A parsed preset: ``generator(**params, rng=seed)`` makes the surface."""

    name: str
    generator: str
    params: dict[str, Any]
    description: str = ""
    seed: int | None = None
    extras: dict[str, Any] = field(default_factory=dict)

    def make(self, **overrides) -> surfaces.Surface:
        """Build the surface; ``overrides`` replace params (``seed`` replaces the seed)."""
        return make_surface(self, **overrides)


def list_presets() -> list[str]:
    """Names of all presets, sorted."""
    return sorted(p.stem for p in presets_dir().glob("*.toml"))


def preset_descriptions() -> dict[str, str]:
    """Each preset of :func:`list_presets` and its one-line description (``spine-mj surface list``)."""
    return {name: load_preset(name).description for name in list_presets()}


def load_preset(name: str) -> Preset:
    """Load a surface preset (a TOML recipe: generator, parameters, seed, calibrated mu).

    Parameters
    ----------
    name : str
        A preset's name (a file stem in :func:`presets_dir`, e.g. ``"paper-fractal"``) or
        the path of a ``.toml`` file.

    Returns
    -------
    Preset

    Raises
    ------
    SpineInputError
        An unknown name, an unreadable file, or a preset whose keys do not check.
    """
    path = Path(name)
    if path.suffix != ".toml":
        path = presets_dir() / f"{name}.toml"
    if not path.is_file():
        known = ", ".join(list_presets()) or "none"
        raise SpineInputError(f"unknown preset {name!r}; known presets: {known}")
    try:
        doc = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise SpineInputError(f"preset {path.name} is not valid TOML: {exc}") from None
    generator = doc.pop("generator", None)
    if generator not in GENERATORS:
        raise SpineInputError(
            f"preset {path.name}: generator must be one of {sorted(GENERATORS)}, got {generator!r}"
        )
    params = doc.pop("params", {})
    if not isinstance(params, dict):
        raise SpineInputError(f"preset {path.name}: [params] must be a table")
    seed = doc.pop("seed", None)
    if seed is not None and (not isinstance(seed, int) or isinstance(seed, bool) or seed < 0):
        raise SpineInputError(f"preset {path.name}: seed must be a non-negative integer, got {seed!r}")
    description = str(doc.pop("description", ""))
    check_generator_params(generator, params, f"preset {path.name}")
    return Preset(
        name=path.stem, generator=generator, params=params, description=description, seed=seed, extras=doc
    )


def preset_mu(preset: Preset | str | surfaces.Surface | None) -> float | None:
    """The calibrated friction coefficient mu_s of a preset (its ``[engagement] mu``).

    ``preset`` is a :class:`Preset`, a preset name, or a surface made from a preset (its
    ``metadata["preset"]``). ``None`` where there is no preset or it has no calibrated mu:
    callers decide their own fallback, so no default hides here.
    """
    if isinstance(preset, surfaces.Surface):
        meta = preset.metadata if isinstance(preset.metadata, dict) else {}
        preset = meta.get("preset")
    if not preset:
        return None
    if isinstance(preset, str):
        preset = load_preset(preset)
    engagement = preset.extras.get("engagement", {})
    value = engagement.get("mu") if isinstance(engagement, dict) else None
    return None if value is None else float(value)


def calibrated_mu(preset: Preset | str) -> float:
    """:func:`preset_mu` for code that needs one (validation, the paper's reproductions).

    Parameters
    ----------
    preset : Preset or str
        A preset or its name.

    Raises
    ------
    SpineInputError
        The preset has no ``[engagement] mu``.
    """
    mu = preset_mu(preset)
    if mu is None:
        name = preset if isinstance(preset, str) else preset.name
        raise SpineInputError(f"preset {name!r} has no [engagement] mu; a calibrated mu_s is needed here")
    return mu


def resolve_mu(
    source: Preset | str | surfaces.Surface | None, mu: float | None = None, *, name: str = "mu"
) -> float:
    """The friction coefficient mu_s a command runs with: the one rule of ``kappa``,
    ``streamline``, ``simulate``, ``sim export``, ``view``, ``reproduce`` and sweep configs.

    ``mu`` when given, else the calibrated ``[engagement] mu`` of ``source``'s preset
    (:func:`preset_mu`: a preset, its name, or a surface made from one). There is no
    fallback value: a surface without a calibrated mu needs one given.

    mu_s must be finite and > 0. mu_s = 0 is refused, not taken as frictionless: the
    engagement condition ``|T| <= mu N`` (Eqs. 1-3) then admits no tangential force, so no
    drive force holds the tip anywhere but on a level floor (kappa = mu = 0 there), every
    slope is a slip region, and the streamline, which follows the engaged direction, is
    undefined; a spine holds by friction, and the harness compares engagement. The
    library's :class:`~spine_mj.sim.TipParams` still takes ``mu_s = 0`` for engine
    experiments.

    Raises
    ------
    SpineInputError
        ``mu`` not a finite number > 0, or none given and ``source`` has no calibrated mu
        (named as ``name``, e.g. ``--mu``).
    """
    if mu is None:
        mu = preset_mu(source)
        if mu is None:
            raise SpineInputError(f"{name} is required for a surface whose preset has no [engagement] mu")
    try:
        value = float(mu)
    except (TypeError, ValueError):
        raise SpineInputError(
            f"{name} (static friction coefficient mu_s) must be a number, got {mu!r}"
        ) from None
    if not (math.isfinite(value) and value > 0):
        raise SpineInputError(
            f"{name} (static friction coefficient mu_s) must be finite and > 0 (mu_s = 0 leaves no "
            f"friction cone to engage in), got {mu!r}"
        )
    return value


def check_generator_params(generator: str, params: dict, where: str) -> None:
    """Refuse parameters that ``generator`` does not take, naming them, ``where`` and the allowed ones."""
    allowed = [p for p in inspect.signature(GENERATORS[generator]).parameters if p != "rng"]
    if generator == "measured":
        allowed = ["file", "channel", "fill", "level", "spacing_m"]
    unknown = sorted(set(params) - set(allowed))
    if unknown:
        raise SpineInputError(
            f"{where}: unknown parameter(s) {unknown} for generator {generator}; "
            f"allowed: {', '.join(allowed)}"
        )


def parse_override(text: str) -> tuple[str, Any]:
    """Parse ``key=value`` with a TOML value (``hurst=0.7``, ``size=[10, 10]``); bare
    words are strings."""
    key, sep, value = text.partition("=")
    key = key.strip()
    if not sep or not key:
        raise SpineInputError(f"override must look like key=value, got {text!r}")
    try:
        parsed = tomllib.loads(f"v = {value.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        parsed = value.strip()
    return key, parsed


def make_surface(preset: Preset | str, **overrides) -> surfaces.Surface:
    """Make the surface a preset describes, with parameters replaced by ``overrides``.

    Parameters
    ----------
    preset : Preset or str
        A preset, or its name for :func:`load_preset`.
    **overrides
        ``seed`` replaces the preset's seed; every other key must be a parameter of the
        preset's generator (e.g. ``hurst`` for ``paper-fractal``).

    Returns
    -------
    Surface
        The surface, its metadata recording the preset's name, generator, parameters and
        seed.

    Examples
    --------
    >>> surface = make_surface("paper-fractal", seed=3, hurst=0.7)
    >>> surface.metadata["preset"], surface.metadata["seed"], surface.metadata["params"]["hurst"]
    ('paper-fractal', 3, 0.7)
    """
    if isinstance(preset, str):
        preset = load_preset(preset)
    overrides = dict(overrides)
    seed = overrides.pop("seed", preset.seed)
    params = dict(preset.params, **overrides)
    check_generator_params(preset.generator, params, f"preset {preset.name}")
    func = GENERATORS[preset.generator]
    takes_rng = "rng" in inspect.signature(func).parameters
    if seed is not None and not takes_rng:
        raise SpineInputError(f"preset {preset.name} ({preset.generator}) takes no seed")
    try:
        surface = func(**params, rng=seed) if takes_rng else func(**params)
    except TypeError as exc:
        raise SpineInputError(f"preset {preset.name}: bad parameter: {exc}") from None
    surface.metadata["preset"] = preset.name
    return surface


def open_surface(spec: str, *, fill: str = "refuse", **overrides) -> surfaces.Surface:
    """The surface a SURFACE argument or a sweep's ``[[surfaces]]`` entry names: a shipped
    example (``example:plu-1.plu``), a saved ``.npz``, a preset (a name of
    :func:`list_presets` or a ``.toml`` recipe, made with ``overrides`` as in
    :func:`make_surface`) or an instrument file (:func:`~spine_mj.surface_io.import_topography`).

    Parameters
    ----------
    spec : str
        ``example:NAME``, a ``.npz`` path, a preset's name or ``.toml`` path, or an instrument
        file's path.
    fill : str
        How an instrument file's missing points are filled
        (:func:`~spine_mj.surface_io.import_topography`: ``refuse``, ``harmonic``, ``nearest``,
        ``mean``); only an instrument file has missing points.
    **overrides
        Generator parameters (and ``seed``) replaced in a preset; none for a file.

    Raises
    ------
    SpineInputError
        ``spec`` names none of these, ``overrides`` are given for a file (only a preset
        has generator parameters), or a ``fill`` for anything but an instrument file.
    """
    spec = examples.resolve(spec)
    path = Path(spec)
    if fill != "refuse" and (spec in list_presets() or path.suffix in (".toml", ".npz")):
        raise SpineInputError(
            f"fill is for an instrument file's missing points, got fill={fill!r} for {spec!r}"
        )
    if spec in list_presets() or path.suffix == ".toml":
        return make_surface(spec, **overrides)
    if overrides:
        raise SpineInputError(
            f"{spec!r} is a surface file: overrides ({', '.join(sorted(overrides))}) are for presets"
        )
    if path.suffix == ".npz":
        return surface_io.load_surface(path)
    if path.is_file():
        return surface_io.import_topography(path, fill=fill)
    raise SpineInputError(
        f"SURFACE must be a .npz file, a preset ({', '.join(list_presets())}), an "
        f"instrument file or an example (spine-mj examples), got {spec!r}"
    )


def make_surface_file(
    output: str | os.PathLike,
    *,
    preset: Preset | str | None = None,
    from_file: str | None = None,
    overrides: dict | None = None,
    import_options: dict | None = None,
    png: str | os.PathLike | None = None,
) -> surfaces.Surface:
    """Make the surface ``preset`` describes (:func:`make_surface` with ``overrides``) or
    import the instrument file ``from_file`` (an ``example:NAME`` too;
    :func:`~spine_mj.surface_io.import_topography` with ``import_options``), and save it as
    the ``.npz`` ``output``, with its PNG preview at ``png`` if given: all written or none
    (``spine-mj surface make``). Returns the surface.

    Raises
    ------
    SpineInputError
        Not exactly one of ``preset`` and ``from_file``; the errors of the maker or reader.
    """
    from spine_mj.atomic import all_or_none

    if (preset is None) == (from_file is None):
        raise SpineInputError("give exactly one of PRESET or --from-file")
    if from_file is not None:
        surface = surface_io.import_topography(examples.resolve(from_file), **(import_options or {}))
    else:
        surface = make_surface(preset, **(overrides or {}))
    with all_or_none(output, png):
        surface_io.save_surface(surface, output)
        if png:
            surface_io.write_preview(surface, png)
    return surface


@dataclass(frozen=True)
class SurfaceInfo:
    """What ``spine-mj surface info`` reports of a surface: its roughness and, where a
    mu_s is known, its predicted drive limits (None otherwise)."""

    unit: str
    roughness: Any
    drive_limits: Any

    def as_dict(self) -> dict:
        """The roughness numbers with ``drive_limits`` (None without a mu_s), JSON-ready
        (:func:`~spine_mj.jsonio.to_jsonable`)."""
        from spine_mj.jsonio import to_jsonable

        limits = None if self.drive_limits is None else self.drive_limits.as_dict()
        return to_jsonable(dict(self.roughness.as_dict(), drive_limits=limits))


def surface_info(
    surface: surfaces.Surface,
    *,
    mu: float | None = None,
    tip_radius: float | None = None,
    psd_png: str | os.PathLike | None = None,
    progress=None,
) -> SurfaceInfo:
    """:func:`~spine_mj.roughness.summarize` of ``surface`` and its
    :func:`~spine_mj.theory.drive_limits.drive_limits` with the one mu rule
    (:func:`resolve_mu`: ``mu``, else the preset's; no limits without either), and the PSD
    plot written to ``psd_png`` if given (``spine-mj surface info``). ``tip_radius`` [the
    surface's length unit]: the tip the limits are of (the one tip rule,
    :func:`spine_mj.sim.scales.resolve_tip_radius`: None the rig's default tip, 0 a point).
    ``progress(done, total)`` hears a big dilation by the tip (the limits').

    Raises
    ------
    SpineInputError
        ``mu`` not finite and > 0, or ``tip_radius`` not finite and >= 0 (named as the
        command's ``--mu`` and ``--tip-radius``).
    """
    from spine_mj import roughness
    from spine_mj.sim.scales import resolve_tip_radius
    from spine_mj.theory.drive_limits import drive_limits

    rough = roughness.summarize(surface)
    limits = None
    if mu is not None or preset_mu(surface) is not None:
        mu = resolve_mu(surface, mu, name="--mu")
        tip_radius = resolve_tip_radius(surface, tip_radius, name="--tip-radius")
        limits = drive_limits(surface, mu, tip_radius=tip_radius, progress=progress)
    if psd_png:
        from spine_mj.plotting import roughness_figure, save_figure

        save_figure(roughness_figure(rough), psd_png)
    return SurfaceInfo(unit=surface.unit, roughness=rough, drive_limits=limits)

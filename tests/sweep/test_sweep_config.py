"""Sweep configs: validation errors name the key, the allowed values and what arrived;
the config hash ignores comments and key order; the analyses' own config checks."""

import pytest
from sweep_support import peak_config, with_, write_config

from spine_mj import sweep
from spine_mj.errors import SpineInputError


@pytest.mark.parametrize(
    "doc, match",
    [
        (with_(extra=1), r"config key extra: unknown key; allowed: sweep, surfaces, starts, grid, drive"),
        (
            with_(sweep__analyses=["quasistatic", "nope"]),
            r"sweep.analyses: allowed values are .*'quasistatic'.*, got 'nope'",
        ),
        (with_(sweep__analyses=["compare"]), r"sweep.analyses: 'compare' needs"),
        (with_(sweep__seed=-1), r"sweep.seed: must be greater than or equal to 0, got -1"),
        (with_(grid__mu=-0.5), r"grid.mu: must be a finite number > 0 .*got -0.5"),
        (
            with_(grid__mu=None, surfaces=[{"preset": "sandpaper-P60"}]),
            r"grid.mu: required by analyses \['quasistatic'\].*sandpaper-P60 has no calibrated mu",
        ),
        (with_(grid__mu=[0.5, 0.5]), r"grid.mu: repeated value"),
        (with_(grid__speed=1.0), r"grid.speed: unknown parameter .*allowed: .*mu"),
        (with_(grid__trajectory="curvy"), r"grid.trajectory: must be one of 'streamline', 'ideal'"),
        (with_(grid__max_steps=1.5), r"grid.max_steps: must be an integer >= 1"),
        (with_(grid__mu={"logspace": [0, 1], "num": 3}), r"grid.mu.logspace: end values must be > 0"),
        (with_(grid__mu={"linspace": [0.1, 1]}), r"grid.mu.num: required"),
        (with_(surfaces=[]), r"config key surfaces: must have at least 1 item\(s\), got \[\]"),
        (with_(surfaces__0__preset="nope"), r"surfaces\[0\].preset: allowed values are .*got 'nope'"),
        (with_(surfaces__0__seeds=[1, 2]), r"surfaces\[0\]: 'paper-single-peak' takes no seed"),
        (with_(surfaces__0__file="x.npz"), r"surfaces\[0\]: give exactly one of preset or file"),
        (with_(surfaces__0__set={"nope": 1}), r"unknown parameter\(s\) \['nope'\]"),
        (with_(surfaces__0__set={"k": "abc"}), r"surfaces\[0\].set: k must be a number, got 'abc'"),
        (
            with_(surfaces__0__set={"sigma_x": -1.0}),
            r"surfaces\[0\].set: sigma_x must be a finite number > 0",
        ),
        (with_(starts=None), r"config key starts: required"),
        (with_(starts__points=[[1.5, 0.5]]), r"starts.points: coordinates must be numbers in \[0, 1\]"),
        (with_(starts__x=[0.5]), r"config key starts: give exactly one of points, x and y, or random"),
        (with_(starts__frame="polar"), r"starts.frame: must be 'relative' or 'absolute', got 'polar'"),
    ],
)
def test_config_errors_name_key_allowed_values_and_what_arrived(doc, match):
    with pytest.raises(SpineInputError, match=match):
        sweep.parse_config(doc)


def test_config_file_errors(tmp_path):
    with pytest.raises(SpineInputError, match="config file not found"):
        sweep.load_config(tmp_path / "missing.toml")
    bad = write_config(tmp_path, "[sweep\nname=1")
    with pytest.raises(SpineInputError, match="is not valid TOML"):
        sweep.load_config(bad)
    missing_file = write_config(
        tmp_path,
        """
        [[surfaces]]
        file = "nowhere.npz"
        [starts]
        points = [[0.5, 0.5]]
        [grid]
        mu = 0.5
    """,
    )
    with pytest.raises(SpineInputError, match=r"surfaces\[0\].file: no such file"):
        sweep.load_config(missing_file)


def test_config_hash_ignores_comments_and_key_order(tmp_path):
    a = peak_config(tmp_path, name="h")
    b = write_config(
        tmp_path,
        "# a comment\n" + a.read_text().replace("[grid]\nmu", "[grid]\n# another\nmu"),
        name="b.toml",
    )
    assert sweep.load_config(a).hash == sweep.load_config(b).hash


def test_mujoco_config_checks():
    doc = with_(sweep__analyses=["engine"], grid__ie=0.1, grid__speed=0.01)
    with pytest.raises(SpineInputError, match=r"grid.ie and grid.speed: give one of them"):
        sweep.parse_config(doc)
    doc = with_(sweep__analyses=["engine"], grid__timestep=1e-4, grid__timestep_factor=0.5)
    with pytest.raises(SpineInputError, match=r"grid.timestep and grid.timestep_factor: give one of them"):
        sweep.parse_config(doc)
    doc = with_(sweep__analyses=["engine"], drive__protocol="pull")
    with pytest.raises(SpineInputError, match=r"drive.protocol: must be one of 'spring', 'ramp'"):
        sweep.parse_config(doc)
    doc = with_(sweep__analyses=["quasistatic"], drive__protocol="spring")
    with pytest.raises(SpineInputError, match=r"drive.protocol: unknown drive parameter"):
        sweep.parse_config(doc)


@pytest.mark.parametrize(
    "doc, message",
    [
        # an unknown key, however deep, is named by its path with the keys allowed there
        (
            with_(surfaces__0__starts={"points": [[0.5, 0.5]], "colour": 1}),
            "config key surfaces[0].starts.colour: unknown key; allowed: frame, points, x, y, random",
        ),
        (
            with_(grid__mu={"linspace": [0.1, 1.0], "num": 2, "step": 1}),
            "config key grid.mu.step: unknown key; allowed: linspace, logspace, num",
        ),
        # a wrong type: what was expected and what arrived
        (
            with_(sweep__store_trajectories="yes"),
            "config key sweep.store_trajectories: must be true or false, got 'yes'",
        ),
        (with_(sweep__seed=1.5), "config key sweep.seed: must be a valid integer, got 1.5"),
        (with_(sweep="fast"), "config key sweep: must be a table, got 'fast'"),
        (
            with_(surfaces__0__starts=[0.5, 0.5]),
            "config key surfaces[0].starts: must be a table, got [0.5, 0.5]",
        ),
        # out of range, with the index of the item in a list
        (
            with_(surfaces=[{"preset": "paper-fractal", "seeds": [1, -2]}]),
            "config key surfaces[0].seeds[1]: must be greater than or equal to 0, got -2",
        ),
        (
            with_(starts={"frame": "absolute", "points": [[0.5, 0.5], [0.5, float("inf")]]}),
            "config key starts.points[1][1]: must be a finite number, got inf",
        ),
        (
            with_(grid__mu={"linspace": [0.1, 1.0], "num": 0}),
            "config key grid.mu.num: must be greater than or equal to 1, got 0",
        ),
        # a grid value is checked against its parameter's declaration, whole list or one value
        (
            with_(grid__tip_radius=[0.1, -1.0]),
            "config key grid.tip_radius: must be a finite number >= 0 (or a list of them), got -1.0",
        ),
        # y without x ended in a KeyError
        (
            with_(starts={"y": [0.5]}),
            "config key starts: give exactly one of points, x and y, or random, got ['y']",
        ),
        # several problems: the first one, and how many others
        (
            with_(sweep__name="", sweep__seed=-1, surfaces__0__preset=3),
            "config key sweep.name: must be a non-empty string, got '' (and 2 other problems)",
        ),
    ],
)
def test_schema_errors_are_one_line_naming_the_key_path(doc, message):
    with pytest.raises(SpineInputError) as err:
        sweep.parse_config(doc)
    assert str(err.value) == message


def test_starts_spec_validates_when_made_directly():
    assert sweep.StartsSpec(frame="absolute", x=-3, y=[-1, -2]).count == 2
    with pytest.raises(ValueError, match=r"coordinates must be numbers in \[0, 1\] in the relative frame"):
        sweep.StartsSpec(points=((2.0, 0.5),))


@pytest.mark.parametrize(
    "protocol, key, value",
    [
        ("static", "K", 3.0),
        ("spring", "start_force", 0.1),
        ("spring", "slide_distance", 1e-3),
        ("ramp", "stiffness", 10.0),
        ("static", "duration", 1.0),
        (["static", "spring"], "K", 3.0),
    ],
)
def test_a_drive_key_that_the_protocol_ignores_is_refused(protocol, key, value):
    doc = with_(sweep__analyses=["engine"], drive__protocol=protocol, **{f"drive__{key}": value})
    with pytest.raises(SpineInputError, match=rf"config key {key} = \[.*\]: the .* drive ignores it"):
        sweep.parse_config(doc)


def test_drive_keys_that_the_protocol_reads_are_accepted():
    for protocol, key, value in (
        ("spring", "K", 3.0),
        ("ramp", "duration", 1.0),
        ("static", "start_force", 0.1),
    ):
        sweep.parse_config(
            with_(sweep__analyses=["engine"], drive__protocol=protocol, **{f"drive__{key}": value})
        )


@pytest.mark.parametrize(
    "analyses, key, value, message",
    [
        (["engine"], "hfield_resolution", 100000, r"hfield_resolution .* in \[4, 8192\], got 100000"),
        (["engine"], "timestep", 1.0, "rests the tip .* deep in the surface"),
        (["engine"], "ie", 1e-30, "more than the limit"),
        (["engine"], "gravity", 0.0, "the tip has no normal preload"),
        (["engine"], "mass", 1e30, "mass_kg must lie in"),
        (["engine"], "length_scale", 1e9, "length_scale_m must lie in"),
        (["quasistatic"], "dl", 1e-300, "a step would be lost in rounding"),
    ],
)
def test_a_value_error_a_run_would_meet_refuses_the_sweep_before_anything_is_written(
    tmp_path, analyses, key, value, message
):
    doc = with_(sweep__analyses=analyses, **{f"grid__{key}": [0.5, value] if key == "dl" else value})
    if analyses == ["engine"]:
        doc["grid"]["mu"] = 0.5
    out = tmp_path / "out"
    with pytest.raises(SpineInputError, match=rf"sweep case \(paper-single-peak.*\): .*{message}"):
        sweep.run_sweep(sweep.parse_config(doc), out, workers=1)
    assert not out.exists()


def test_a_sweep_over_a_surface_file_with_an_unknown_unit_is_refused(tmp_path):
    import numpy as np

    from spine_mj import presets, surface_io

    path = surface_io.save_surface(presets.make_surface("paper-single-peak").sample(16), tmp_path / "s.npz")
    data = dict(np.load(path))
    data["unit"] = np.array("banana")
    np.savez(path, **data)
    doc = with_(surfaces=[{"file": str(path)}], grid__mu=0.5)
    with pytest.raises(SpineInputError, match="unit must be '1'"):
        sweep.run_sweep(sweep.parse_config(doc), tmp_path / "out", workers=1)
    assert not (tmp_path / "out").exists()


def test_the_old_analysis_name_mujoco_is_refused_naming_engine():
    """The analysis that runs the grid's engine (MuJoCo or Bullet) is ``engine``; a saved
    config naming it ``mujoco`` gets one line saying what to write instead."""
    with pytest.raises(SpineInputError, match=r"sweep.analyses: .*'mujoco' is now 'engine'.*write 'engine'"):
        sweep.parse_config(with_(sweep__analyses=["quasistatic", "mujoco"]))

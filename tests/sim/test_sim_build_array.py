"""The one way to an array and its carriage's drive (``spine-mj array`` and a sweep's
``array`` analysis): the speed drive is the single rig's spring drive, the force pull's
rate per spine has the same drive speed's equivalent."""

import pytest
from sim_rigs import MU

from spine_mj import sim, surfaces
from spine_mj.errors import SpineInputError

LAYOUT = sim.Layout(rows=1, cols=2, spacing=0.3, spacing_unit="surface")


@pytest.fixture(scope="module")
def rig():
    return sim.build_rig(surfaces.corrugation(), mu=MU, hfield_resolution=41)


def test_the_speed_drive_is_the_spring_drive_of_the_same_inputs(rig):
    arr, drive = sim.build_array(rig, LAYOUT, "speed", ie=1e-2, stiffness_number=10, duration_s=0.5)
    assert not arr.force_control and arr.layout == LAYOUT and arr.rig is rig
    assert drive == sim.build_drive(rig.scales, "spring", ie=1e-2, stiffness_number=10, duration_s=0.5)


def test_the_force_pull_rises_at_the_drive_speeds_equivalent(rig):
    arr, drive = sim.build_array(rig, LAYOUT, "force", ie=1e-2, stiffness_number=10)
    assert arr.force_control
    speed = rig.scales.speed_for(1e-2)
    assert drive.rate_n_s == pytest.approx(rig.scales.force_rate_for(speed), rel=1e-12)
    assert rig.scales.equivalent_speed(drive.rate_n_s) == pytest.approx(speed, rel=1e-12)
    assert drive.stiffness_n_m == pytest.approx(rig.scales.stiffness_for(10), rel=1e-12)


@pytest.mark.parametrize(
    ("drive", "options", "message"),
    [
        ("force", {"duration_s": 1.0}, "duration is for the speed drive"),
        ("pulled", {}, "array drive must be one of speed, force, got 'pulled'"),
        ("speed", {"stiffness_number": -1.0}, "K"),
    ],
)
def test_inputs_that_make_no_drive_are_named(rig, drive, options, message):
    with pytest.raises(SpineInputError, match=message):
        sim.build_array(rig, LAYOUT, drive, **options)


def test_a_layout_seed_must_be_a_seed():
    with pytest.raises(SpineInputError, match="layout seed must be an integer >= 0, got -1"):
        sim.Layout(kind="random", rows=2, cols=2, seed=-1)


@pytest.mark.parametrize("drive", ["speed", "force"])
def test_the_command_lines_array_runs_at_the_arrays_own_pace(rig, drive):
    surf = surfaces.corrugation()
    arr, carriage, ie = sim.build_array_on(
        surf, LAYOUT, drive, mu=MU, stiffness_number=10, hfield_resolution=41
    )
    k = rig.scales.stiffness_for(10)
    assert ie == sim.array_ie(rig.scales, mu=MU, force_control=drive == "force", stiffness_n_m=k)
    assert (carriage, arr.force_control) == (
        sim.build_array(rig, LAYOUT, drive, ie=ie, stiffness_number=10)[1],
        drive == "force",
    )
    _, _, given = sim.build_array_on(surf, LAYOUT, drive, mu=MU, ie=3e-3, hfield_resolution=41)
    assert given == 3e-3

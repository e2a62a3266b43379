"""MuJoCo's ``impratio`` on the stick-slip scripts' flat strip and one-slip run (issue 42
item 5): the frictional-to-normal impedance ratio reaches the model, and a bad value is one
error line naming the option."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from spine_mj import presets

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def engines(analysis_script):
    return analysis_script("stickslip_engines")


@pytest.fixture(scope="module")
def flat(engines):
    part = engines.crop(presets.make_surface("abbm-short"), 100.0, 130.0)
    return dataclasses.replace(part, heights=np.zeros_like(part.heights))


def test_the_flat_rig_carries_impratio(engines, flat):
    rule = engines.flat_rig(flat, "mujoco", 1e-5, 2.0, 0.5)
    low = engines.flat_rig(flat, "mujoco", 1e-5, 2.0, 0.5, solref_steps=(4, 0.5), impratio=10.0)
    dt = rule.engine.timestep_s
    assert rule.engine.impratio == 1.0 and rule.model.opt.impratio == 1.0  # the rule's
    assert low.engine.impratio == 10.0 and low.model.opt.impratio == pytest.approx(10.0)
    assert low.engine.timestep_s == dt
    assert rule.engine.solref == pytest.approx((2 * dt, 1.0), rel=1e-12)
    assert low.engine.solref == pytest.approx((4 * dt, 0.5), rel=1e-12)


def test_flat_settings_reads_an_optional_impratio(analysis_script):
    cost = analysis_script("stickslip_contact_cost")
    assert cost.flat_settings("2:1,4:0.5:10") == [(2.0, 1.0, None), (4.0, 0.5, 10.0)]


@pytest.mark.parametrize("text", ["2:1:0", "2", "2:soft", "4:0.5:-1", "2:1:1:1"])
def test_a_bad_flat_setting_is_one_error_line(analysis_script, capsys, text):
    cost = analysis_script("stickslip_contact_cost")
    with pytest.raises(SystemExit) as exit_:
        cost.main(["--flat", text])
    err = capsys.readouterr().err.strip().splitlines()
    assert exit_.value.code == 2
    assert "argument --flat" in err[-1] and "--flat expects" in err[-1]


@pytest.mark.parametrize("text", ["0", "-3", "stiff"])
def test_a_bad_impratio_is_one_error_line(analysis_script, capsys, text):
    work = analysis_script("stickslip_contact_work")
    with pytest.raises(SystemExit) as exit_:
        work.main(["--impratio", text])
    err = capsys.readouterr().err.strip().splitlines()
    assert exit_.value.code == 2
    assert f"--impratio expects a positive number, got {text!r}" in err[-1]


def test_batch_means_widen_for_a_correlated_series(engines):
    rng = np.random.default_rng(3)
    white = rng.normal(size=20_000)
    # white noise: batch means agree with std / sqrt(n) to within their own scatter
    assert engines.batch_mean_se(white) == pytest.approx(white.std() / np.sqrt(white.size), rel=0.5)
    # a slow ring (period 2 000 rows) inflates the mean's error far beyond std / sqrt(n)
    ring = np.sin(2 * np.pi * np.arange(20_000) / 2000 + 0.3) + 0.01 * white
    assert engines.batch_mean_se(ring) > 5 * ring.std() / np.sqrt(ring.size)

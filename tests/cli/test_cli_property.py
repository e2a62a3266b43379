"""Property test of the command line: random options and configs end in exit code 0 or
2, never a traceback, and leave no partial file behind."""

import json
import math
import os

from click.testing import CliRunner
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from spine_mj import presets
from spine_mj.cli import main

NUMBERS = st.sampled_from(
    [math.nan, math.inf, -math.inf, 1e300, -1e300, -1.0, 0.0, 1e-12, 0.5, 2.0, 3, -7, 10**20]
)
TOML_VALUES = st.one_of(
    NUMBERS.map(lambda v: "nan" if v != v else {math.inf: "inf", -math.inf: "-inf"}.get(v, repr(v))),
    st.sampled_from(["true", '"text"', "[1, 2]", "[1e9, 1e9]", "{ a = 1 }", "not toml ["]),
    st.text(alphabet="abc=[]{}\"' 019.-", max_size=8),
)
PRESETS = st.sampled_from(presets.list_presets())
KEYS = st.one_of(
    st.sampled_from(["hurst", "size", "n_peaks", "seed", "rms", "height", "spacing", "resolution", "file"]),
    st.text(alphabet="abcdefghij_", min_size=1, max_size=8),
)
#: More examples for a longer search: SPINE_MJ_PROPERTY_SCALE=10 pytest tests/cli/test_cli_property.py
SCALE = int(os.environ.get("SPINE_MJ_PROPERTY_SCALE", "1"))
SETTINGS = settings(
    max_examples=12 * SCALE,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


def invoke(args):
    result = CliRunner().invoke(main, [str(a) for a in args])
    assert result.exit_code in (0, 2), (args, result.output, result.exception)
    assert result.exception is None or isinstance(result.exception, SystemExit), (args, result.exception)
    assert "Traceback" not in result.output, (args, result.output)
    event(f"exit code {result.exit_code}")
    return result


def no_partial_files(folder, result, expected=()):
    left = sorted(p.name for p in folder.rglob("*") if p.is_file())
    assert not [n for n in left if n.startswith(".") and n != ".sweep.lock"], left
    if result.exit_code == 2:
        assert not set(left) & set(expected), (left, result.output)


@SETTINGS
@given(preset=PRESETS, sets=st.lists(st.tuples(KEYS, TOML_VALUES), max_size=3), hurst=st.none() | NUMBERS)
def test_surface_make_random_overrides(tmp_path_factory, preset, sets, hurst):
    out = tmp_path_factory.mktemp("make")
    args = ["surface", "make", preset, "-o", out / "s.npz"]
    for k, v in sets:
        args += ["--set", f"{k}={v}"]
    if hurst is not None:
        args += ["--hurst", hurst]
    result = invoke(args)
    no_partial_files(out, result, ["s.npz"])


@settings(SETTINGS, max_examples=5 * SCALE)
@given(
    mass=st.none() | NUMBERS,
    mu=st.none() | NUMBERS,
    speed=st.none() | NUMBERS,
    timestep=st.none() | st.sampled_from([math.nan, -1e-3, 0.0, 1e-4, 1e300]),
    start=st.sampled_from(["-3,-1", "nan,0", "1e300,0", "a,b", "0"]),
)
def test_simulate_random_numbers(tmp_path_factory, mass, mu, speed, timestep, start):
    out = tmp_path_factory.mktemp("sim")
    args = ["simulate", "paper-single-peak", "--start", start, "--duration", 0.01]
    args += ["--resolution", 21, "--out", out / "run"]
    for name, value in (("--mass", mass), ("--mu", mu), ("--speed", speed), ("--timestep", timestep)):
        if value is not None:
            args += [name, value]
    result = invoke(args)
    no_partial_files(out, result, ["trajectory.parquet", "run.png", "summary.json"])


SWEEP_VALUES = st.one_of(
    NUMBERS, st.sampled_from(["x", True, [], [0.5, 0.5], {"linspace": [0, 1], "num": 10**9}, {"num": 2}])
)


@st.composite
def sweep_docs(draw):
    doc = {
        "sweep": {
            "name": "p",
            "analyses": draw(st.sampled_from([["quasistatic"], "quasistatic", ["nope"], []])),
        },
        "surfaces": [{"preset": draw(PRESETS)}],
        "starts": {"points": [[0.1, 0.5]]},
        "grid": {"dl": 0.1, "max_steps": 50},
    }
    for _ in range(draw(st.integers(0, 2))):
        table = draw(st.sampled_from(["sweep", "grid", "starts", "drive", "surfaces0", "top"]))
        key = draw(st.one_of(st.sampled_from(["mu", "seed", "dl", "num", "random", "n_seeds", "x"]), KEYS))
        value = draw(SWEEP_VALUES)
        node = (
            doc
            if table == "top"
            else doc["surfaces"][0]
            if table == "surfaces0"
            else doc.setdefault(table, {})
        )
        node[key] = value
    return doc


def to_toml(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "nan" if value != value else {math.inf: "inf", -math.inf: "-inf"}.get(value, repr(value))
    if isinstance(value, (int, str)):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(to_toml(v) for v in value) + "]"
    return "{ " + ", ".join(f"{json.dumps(k)} = {to_toml(v)}" for k, v in value.items()) + " }"


def is_tables(value):
    return isinstance(value, list) and value and all(isinstance(v, dict) for v in value)


def document(doc):
    plain = {k: v for k, v in doc.items() if not isinstance(v, dict) and not is_tables(v)}
    lines = [f"{json.dumps(k)} = {to_toml(v)}" for k, v in plain.items()]
    for name, table in doc.items():
        if isinstance(table, dict):
            lines += [f"[{name}]"] + [f"{json.dumps(k)} = {to_toml(v)}" for k, v in table.items()]
        elif is_tables(table):
            for entry in table:
                lines += [f"[[{name}]]"] + [f"{json.dumps(k)} = {to_toml(v)}" for k, v in entry.items()]
    return "\n".join(lines) + "\n"


@settings(SETTINGS, max_examples=20 * SCALE)
@given(doc=sweep_docs(), workers=st.sampled_from([None, 0, 1, 10**6]))
def test_sweep_random_configs(tmp_path_factory, doc, workers):
    folder = tmp_path_factory.mktemp("sweep")
    cfg = folder / "c.toml"
    cfg.write_text(document(doc))
    args = ["sweep", cfg, "--out", folder / "out", "--quiet"]
    if workers is not None:
        args += ["--workers", workers]
    result = invoke(args)
    if result.exit_code == 2:
        assert not (folder / "out").exists(), result.output
    no_partial_files(folder, result)

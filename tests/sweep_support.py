"""Shared by the sweep tests (tests/sweep/test_sweep_*.py): small configs and their helpers."""

import json
import textwrap

from spine_mj import sweep

PEAK_QS = """
[sweep]
name = "{name}"
analyses = ["quasistatic"]

[[surfaces]]
preset = "paper-single-peak"

[starts]
x = [0.05]
y = {{ linspace = [0.1, 0.9], num = {ny} }}

[grid]
mu = {{ linspace = [0.4, 1.6], num = {nmu} }}
dl = {dl}
"""


def write_config(tmp_path, text, name="sweep.toml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def peak_config(tmp_path, *, nmu=4, ny=3, dl=0.02, name="peak"):
    return write_config(tmp_path, PEAK_QS.format(name=name, nmu=nmu, ny=ny, dl=dl))


def metrics_frame(out_dir):
    df = sweep.load_runs(out_dir).drop(columns=["time_s", "cpu_s"])
    return df.sort_values("run_id").reset_index(drop=True)


BASE = {
    "sweep": {"analyses": ["quasistatic"]},
    "surfaces": [{"preset": "paper-single-peak"}],
    "starts": {"points": [[0.1, 0.5]]},
    "grid": {"mu": 0.5},
}


def with_(**changes):
    doc = json.loads(json.dumps(BASE))
    for path, value in changes.items():
        *head, last = path.split("__")
        node = doc
        for key in head:
            node = node[int(key)] if isinstance(node, list) else node.setdefault(key, {})
        if value is None:
            del node[last]
        else:
            node[last] = value
    return doc

"""Re-run the hostile-input probes of issue 28 from a folder outside the repository.

Each probe is a command line with what must come of it: ``refuse`` (exit 2, one line
``Error: ...``, none of its outputs written) or ``ok`` (exit 0, with a text the output
must hold). Prints one line per probe and the tally. Run from anywhere:

    python analysis/hostile_probes.py [--novideo /path/to/venv-without-imageio/bin]

Probes that need a real scheduler, a full disk or a killed validation are covered by the
test suite instead (tests/sweep/test_sweep_scheduler.py, tests/test_errors.py).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

SPINE = [str(Path(sys.executable).with_name("spine-mj"))]


def sweep_config(folder: Path, name: str, body: str) -> str:
    path = folder / f"{name}.toml"
    path.write_text(textwrap.dedent(body))
    return str(path)


MUJOCO = """
[sweep]
analyses = ["{analysis}"]
[[surfaces]]
{surface}
[starts]
frame = "absolute"
points = [[-3.0, -2.0]]
[{table}]
{key}
"""


def probes(work: Path, novideo: str | None) -> list[tuple[str, list[str], str, str, dict]]:
    py = sys.executable
    make = [
        py,
        "-c",
        "import numpy as np, sys; from spine_mj import presets, surface_io; "
        "s = presets.make_surface('paper-single-peak').sample(32); "
        "surface_io.save_surface(s, 'u.npz'); d = dict(np.load('u.npz')); "
        "d['unit'] = np.array(sys.argv[1]); np.savez(sys.argv[2], **d)",
    ]
    subprocess.run([*make, "banana", "banana.npz"], cwd=work, check=True)
    subprocess.run([*make, "", "empty.npz"], cwd=work, check=True)
    import zipfile

    with zipfile.ZipFile(work / "hello.npz", "w") as z:
        z.writestr("hello.txt", "hello")
    flat = (
        "import numpy as np; from spine_mj import surfaces, surface_io; x = np.linspace(0, 1, 16); "
        "surface_io.save_surface(surfaces.GridSurface(heights=np.zeros((16, 16)), x=x, y=x), 'flat.npz')"
    )
    subprocess.run([py, "-c", flat], cwd=work, check=True)
    subprocess.run(
        [
            *SPINE,
            "simulate",
            "paper-single-peak",
            "--start",
            "-3,-1",
            "--resolution",
            "41",
            "--duration",
            "0.01",
            "--out",
            "rec",
        ],
        cwd=work,
        check=True,
        capture_output=True,
    )
    out = []

    def add(name, args, expect, needle="", env=None):
        out.append((name, args, expect, needle, env or {}))

    # README from any folder
    add(
        "README surface make --from-file example:plu-1.plu",
        [
            *SPINE,
            "surface",
            "make",
            "--from-file",
            "example:plu-1.plu",
            "--fill",
            "harmonic",
            "--spacing",
            "2e-6",
            "-o",
            "scan.npz",
        ],
        "ok",
        "wrote",
    )
    add(
        "README sweep example:mujoco-ie.toml (config read)",
        [
            py,
            "-c",
            "from spine_mj import sweep, examples; "
            "print(sweep.load_config(examples.resolve('example:mujoco-ie.toml')).name)",
        ],
        "ok",
        "mujoco-ie",
    )
    # optional extras and the rendering backend
    sim = [
        *SPINE,
        "simulate",
        "paper-single-peak",
        "--start",
        "-3,-2",
        "--resolution",
        "41",
        "--duration",
        "0.01",
    ]
    for gl in ("bogus", "osmesa"):
        add(
            f"MUJOCO_GL={gl} simulate --render",
            [*sim, "--render", "--out", "gl"],
            "refuse",
            "MUJOCO_GL",
            {"MUJOCO_GL": gl},
        )
    if novideo:
        nv = [str(Path(novideo) / "spine-mj")]
        add(
            "no [video]: simulate --render",
            [*nv, *sim[1:], "--render", "--out", "nv"],
            "refuse",
            "spine-mj[video]",
        )
        add(
            "no [video]: headless replay",
            [*nv, "replay", "rec", "--mp4", "nv.mp4"],
            "refuse",
            "spine-mj[video]",
        )
    # options accepted and ignored
    for opt in (["--fill", "harmonic"], ["--spacing", "1e-6"], ["--no-level"], ["--channel", "3"]):
        add(
            f"surface make preset {opt[0]}",
            [*SPINE, "surface", "make", "paper-single-peak", *opt, "-o", "m.npz"],
            "refuse",
            opt[0],
        )
    for opt in (["--seed", "3"], ["--hurst", "0.7"], ["--set", "nx=5"]):
        add(
            f"surface make --from-file {opt[0]}",
            [*SPINE, "surface", "make", "--from-file", "example:di-1.di", *opt, "-o", "m.npz"],
            "refuse",
            opt[0],
        )
    for v in ("overlap=nan", "overlap=2", 'anisotropic="no"'):
        add(
            f"surface make --set {v}",
            [*SPINE, "surface", "make", "paper-random-convex", "--set", v, "-o", "m.npz"],
            "refuse",
            v.split("=")[0],
        )
    add(
        "replay headless --duration",
        [*SPINE, "replay", "rec", "--speed", "0.01", "--duration", "20", "--mp4", "r.mp4"],
        "refuse",
        "--duration",
    )
    # sweep keys ignored, and value errors found only at run time
    ignored = [
        ("static", "K = 3.0"),
        ("spring", "start_force = 0.1"),
        ("spring", "slide_distance = 0.001"),
        ("ramp", "stiffness = 10.0"),
        ("static", "duration = 1.0"),
    ]
    for protocol, kv in ignored:
        cfg = sweep_config(
            work,
            f"ign-{kv.split()[0]}",
            MUJOCO.format(
                analysis="engine",
                surface='preset = "paper-single-peak"',
                table="drive",
                key=f'protocol = "{protocol}"\n{kv}',
            ),
        )
        add(
            f"sweep {kv} with {protocol}",
            [*SPINE, "sweep", cfg, "--out", f"o-{kv.split()[0]}"],
            "refuse",
            "ignores it",
        )
    for kv, analysis in (
        ("hfield_resolution = 100000", "engine"),
        ("timestep = 1.0", "engine"),
        ("ie = 1e-30", "engine"),
        ("gravity = 0.0", "engine"),
        ("mass = 1e30", "engine"),
        ("length_scale = 1e9", "engine"),
        ("dl = 1e-300", "quasistatic"),
    ):
        cfg = sweep_config(
            work,
            f"val-{kv.split()[0]}",
            MUJOCO.format(analysis=analysis, surface='preset = "paper-single-peak"', table="grid", key=kv),
        )
        add(f"sweep {kv}", [*SPINE, "sweep", cfg, "--out", f"v-{kv.split()[0]}"], "refuse", "sweep case")
    cfg = sweep_config(
        work,
        "aniso",
        'starts = {points = [[0.1, 0.5]]}\n[[surfaces]]\npreset = "paper-random-convex"\n'
        'set = { anisotropic = "no" }\n[grid]\nmu = 0.5\n'.replace("starts = {points = [[0.1, 0.5]]}\n", "")
        + "[starts]\npoints = [[0.1, 0.5]]\n",
    )
    add(
        'sweep set = { anisotropic = "no" }',
        [*SPINE, "sweep", cfg, "--out", "o-aniso"],
        "refuse",
        "anisotropic",
    )
    cfg = sweep_config(
        work,
        "banana-sweep",
        '[[surfaces]]\nfile = "banana.npz"\n[starts]\npoints = [[0.1, 0.5]]\n[grid]\nmu = 0.5\n',
    )
    add(
        "sweep over a surface with unit banana", [*SPINE, "sweep", cfg, "--out", "o-banana"], "refuse", "unit"
    )
    # a wrong physical answer
    for mu in ("1e8", "1e15", "1e100", "1e308"):
        add(
            f"kappa --mu {mu}",
            [*SPINE, "kappa", "paper-single-peak", "--mu", mu, "-o", f"k{mu}.png"],
            "ok",
            "slip 0.0 %",
        )
    # nonsense that runs
    add("simulate --preload 1e30", [*sim, "--preload", "1e30", "--out", "pl"], "refuse", "preload")
    add("simulate --mu 0 (the mu rule: issue 24)", [*sim, "--mu", "0", "--out", "mu0"], "refuse", "mu")
    for f in ("banana.npz", "empty.npz"):
        add(f"surface info {f}", [*SPINE, "surface", "info", f], "refuse", "unit")
    add(
        "surface make 2000 Gaussians",
        [*SPINE, "surface", "make", "paper-random-convex", "--set", "n_peaks=2000", "-o", "many.npz"],
        "ok",
        "wrote",
    )
    add("surface info 2000 Gaussians", [*SPINE, "surface", "info", "many.npz"], "ok", "not estimated")
    # a traceback, a hang, a partial output
    add("surface info zip not npz", [*SPINE, "surface", "info", "hello.npz"], "refuse", "hello.npz")
    add(
        "reproduce fractal-hurst --surfaces 1e8",
        [
            *SPINE,
            "reproduce",
            "fractal-hurst",
            "--quick",
            "--surfaces",
            "100000000",
            "--workers",
            "1",
            "--out",
            "rp",
        ],
        "refuse",
        "--surfaces",
    )
    add(
        "validate --workers 100",
        [*SPINE, "validate", "--quick", "--workers", "100", "--out", "v"],
        "refuse",
        "--workers",
    )
    # errors longer than one line
    add("unknown global option", [*SPINE, "--bogus"], "refuse", "--bogus")
    add("bare reproduce", [*SPINE, "reproduce"], "refuse", "Choose from")
    add(
        "surface info, no slope correlation length (reports what it can, issue 44)",
        [*SPINE, "surface", "info", "flat.npz"],
        "ok",
        "no slope correlation length",
    )
    # issue 36: options the chosen layout or executor would ignore, and help examples
    arr = [*SPINE, "array", "corrugation", "--rows", "1", "--cols", "2", "--out", "arr"]
    add("array --layout random --seed -1", [*arr, "--layout", "random", "--seed", "-1"], "refuse", "--seed")
    add("array --layout grid --seed 5", [*arr, "--layout", "grid", "--seed", "5"], "refuse", "--seed")
    add(
        "sweep --scheduler with --workers",
        [
            *SPINE,
            "sweep",
            "example:paper-quasistatic.toml",
            "--out",
            "s",
            "--scheduler",
            "tcp://x:1",
            "--workers",
            "2",
        ],
        "refuse",
        "--workers",
    )
    add(
        "surface info SCAN --tip-radius without --mu",
        [*SPINE, "surface", "info", "example:plu-1.plu", "--tip-radius", "1e-6"],
        "refuse",
        "--tip-radius",
    )
    add(
        "streamline's help example (--out)",
        [*SPINE, "streamline", "paper-single-valley", "--mu", "1.2", "--start", "-3,-1", "--out", "sl"],
        "ok",
        "wrote",
    )
    _issue44(add, work, py)
    return out


def _issue44(add, work: Path, py: str) -> None:
    """Issue 44's families: planes' arguments, Bullet's step, the engines study's
    arguments, nested JSON, engine and drive keys a sweep would not apply, refusals that
    only a combination of the grid makes, memory beyond the budget (the fractal's
    synthesis, simulate's hfield), narrow strips and planes that must run, a heightfield
    past pybullet's limit and a rail Bullet does not have."""
    plane = [*SPINE, "surface", "make", "plane", "-o", "p.npz", "--set"]
    for setting, needle in (
        ('slope_deg="steep"', "slope_deg"),
        ("azimuth_deg=inf", "azimuth_deg"),
        ("unit=banana", "unit"),
        ("n=100000", "100000 x 100000"),
    ):
        add(f"surface make plane --set {setting}", [*plane, setting], "refuse", needle)
    sim_bullet = [*SPINE, "simulate", "paper-single-peak", "--start", "-3,-1", "--out", "b"]
    add(
        "simulate --engine bullet --timestep nan",
        [*sim_bullet, "--engine", "bullet", "--timestep", "nan"],
        "refuse",
        "timestep",
    )
    engines = [*SPINE, "compare-engines"]
    (work / "a-file").write_text("")
    engine_args = [
        (["--out", "e", "--fractal", "-1"], "--fractal"),
        (["--out", "e", "--headlines", "-1"], "--headlines"),
        (["--out", "e", "--workers", "0"], "--workers"),
        (["--out", "e", "--fractal", "abc"], "--fractal"),
        (["--out", "e", "--bogus"], "--bogus"),
        ([], "--out"),
        (["--out", "a-file"], "a-file"),
        (["--out", "a-file/e"], "a-file"),
    ]
    if sys.platform.startswith("linux"):  # procfs takes no new file, not even root's
        engine_args.append((["--out", "/proc/self/e"], "cannot write /proc/self/e/engines.json"))
    for args, needle in engine_args:
        add(f"compare-engines {' '.join(args) or '(no arguments)'}", [*engines, *args], "refuse", needle)
    add(
        "python -m spine_mj.validate.engines (the study's old entry point)",
        [py, "-m", "spine_mj.validate.engines", "--out", "e", "--fractal", "-1"],
        "refuse",
        "spine-mj compare-engines",
    )
    (work / "deep.json").write_text("[" * 100_000 + "]" * 100_000)
    check = str(Path(__file__).with_name("reproduction_check.py"))
    add("reproduction_check.py on deeply nested JSON", [py, check, "deep.json"], "refuse", "nested too deep")
    base = """
    [sweep]
    analyses = {analyses}
    [[surfaces]]
    preset = "{preset}"
    [starts]
    x = [0.05]
    y = [0.5]
    {tables}
    """
    configs = {
        "bullet with integrator": (
            '["engine"]',
            "paper-single-peak",
            '[grid]\nengine = "bullet"\nintegrator = "euler"',
            "engine bullet",
        ),
        "bullet with timestep_factor": (
            '["engine"]',
            "paper-single-peak",
            '[grid]\nengine = "bullet"\ntimestep_factor = 0.5',
            "engine bullet",
        ),
        **{
            f"bullet with {key}": (
                '["engine"]',
                "paper-single-peak",
                f'[grid]\nengine = "bullet"\n{key} = {value}',
                "engine bullet",
            )
            for key, value in (
                ("noslip_iterations", "5"),
                ("tolerance", "1e-9"),
                ("solref_dampratio", "0.5"),
                ("cone", '"pyramidal"'),
            )
        },
        "array protocol static": ('["array"]', "corrugation", '[drive]\nprotocol = "static"', "static"),
        "array force with duration": (
            '["array"]',
            "corrugation",
            '[drive]\nduration = 0.1\n[array]\narray_drive = "force"',
            "force",
        ),
        "grid swing ie x K": (
            '["quasistatic", "engine", "compare"]',
            "paper-fractal",
            "[drive]\nie = [1e-4, 1e-3]\nK = [10, 100]",
            "K = 100",
        ),
        "grid steps ie x timestep_factor": (
            '["engine"]',
            "paper-single-peak",
            "[drive]\nie = [1.0, 1e-3]\n[grid]\ntimestep_factor = [1.0, 1e-3]",
            "steps",
        ),
        "grid sizes resolution x refinement": (
            '["engine"]',
            "paper-single-peak",
            "[grid]\nhfield_resolution = [61, 1500]\nhfield_refinement = [1, 6]",
            "samples a side",
        ),
        "array spines off the surface": (
            '["array"]',
            "corrugation",
            '[array]\nspacing = 2.0\nspacing_unit = "surface"',
            "outside the surface",
        ),
        "array staggered 3 x 40 off the surface": (
            '["array"]',
            "corrugation",
            '[array]\nlayout = "staggered"\nrows = 3\ncols = 40\nspacing = 0.2\nspacing_unit = "surface"',
            "outside the surface",
        ),
        "array random 8 x 8 at spacing 0.001": (
            '["array"]',
            "corrugation",
            '[array]\nlayout = "random"\nrows = 8\ncols = 8\nspacing = 0.001\nspacing_unit = "surface"',
            "too small for 64 random spines",
        ),
    }
    for name, (analyses, preset, tables, needle) in configs.items():
        body = base.format(analyses=analyses, preset=preset, tables=tables)
        cfg = sweep_config(work, name.replace(" ", "-"), body)
        add(
            f"sweep: {name}",
            [*SPINE, "sweep", cfg, "--out", "s44", "--workers", "1", "--quiet"],
            "refuse",
            needle,
        )
    small = {"SPINE_MJ_MEMORY_BUDGET": "1G"}
    add(
        "surface make paper-fractal nx=8192 (1 GiB budget)",
        [*SPINE, "surface", "make", "paper-fractal", "--set", "nx=8192", "-o", "f.npz"],
        "refuse",
        "fractal_fbm: a 8192 x 8192 grid would need",
        small,
    )
    add(
        "simulate --resolution 8192 (1 GiB budget)",
        [*sim_bullet[:-2], "--resolution", "8192", "--out", "r8192"],
        "refuse",
        "an hfield of 8192 x 8192 samples",
        small,
    )
    ie = [round(1e-5 * (1 + i * 1e-3), 9) for i in range(999)]
    stiff = [round(30 + 0.01 * i, 4) for i in range(1001)]
    body = base.format(
        analyses='["engine"]', preset="paper-single-peak", tables=f"[drive]\nie = {ie}\nK = {stiff}"
    )
    add(
        "sweep of 999,999 cases (64 MiB budget)",
        [*SPINE, "sweep", sweep_config(work, "million", body), "--out", "s1m", "--quiet"],
        "refuse",
        "preparing the sweep's 999,999 cases",
        {"SPINE_MJ_MEMORY_BUDGET": "64M"},
    )
    strips = (
        "import numpy as np; from spine_mj import surfaces, surface_io\n"
        "for name, x, y in (('track', np.linspace(0, 200, 4001), np.linspace(0, 4, 21)),\n"
        "                   ('strip', np.arange(100001) * 0.125, np.arange(9) * 0.125)):\n"
        "    h = 0.3 * np.sin(1.3 * x)[None, :] + 0.05 * np.cos(1.7 * y)[:, None]\n"
        "    surface_io.save_surface(surfaces.GridSurface(heights=h, x=x, y=y), name + '.npz')"
    )
    subprocess.run([py, "-c", strips], cwd=work, check=True)
    for name, start in (("track", "10,2"), ("strip", "100,0.5")):
        add(f"surface info {name}", [*SPINE, "surface", "info", f"{name}.npz", "--mu", "0.5"], "ok", "l_s")
        for engine in ("mujoco", "bullet"):
            run = ["--mu", "0.5", "--start", start, "--duration", "0.3", "--engine", engine]
            add(
                f"simulate {name} --engine {engine}",
                [*SPINE, "simulate", f"{name}.npz", *run, "--out", f"{name}-{engine}"],
                "ok",
                "end: completed",
            )
    for setting in ("slope_deg=0", "slope_deg=20"):
        made = [*SPINE, "surface", "make", "plane", "-o", f"plane-{setting[-2:]}.npz", "--set", setting]
        subprocess.run(made, cwd=work, check=True, capture_output=True)
        add(
            f"surface info plane {setting}",
            [*SPINE, "surface", "info", f"plane-{setting[-2:]}.npz"],
            "ok",
            "no slope correlation length",
        )
    add(
        "simulate --engine bullet --resolution 1449 (past pybullet's upload buffer)",
        [*sim_bullet[:-2], "--engine", "bullet", "--resolution", "1449", "--out", "b1449"],
        "refuse",
        "1449 x 1449 samples is more than pybullet takes",
    )
    add(
        "simulate --line --engine bullet",
        [*sim_bullet, "--engine", "bullet", "--line"],
        "refuse",
        "line: not read by engine bullet",
    )
    _issue44_leftovers(add, work, base)


def _issue44_leftovers(add, work: Path, base: str) -> None:
    """Issue 44's last round: starts on the domain's edge (a run ended left_domain at once),
    a nonsense hfield_refinement, hfield limits refused on the predicted sides before any
    sizing (Bullet's on a fractal grid, the memory of a refined hfield in both engines),
    and the shared --fill option."""
    edge = [*SPINE, "simulate", "paper-single-peak", "--ie", "1e-2"]
    for start, needle in (("-5,-1", "on the edge of the surface's domain"), ("-4.99,-1", "within 0.05")):
        add(
            f"simulate --start {start} (domain x in [-5, 5])",
            [*edge, "--start", start, "--out", "e"],
            "refuse",
            needle,
        )
    configs = {
        "start on the domain's edge": (
            base.replace("x = [0.05]\n    y = [0.5]", 'frame = "absolute"\n    points = [[-5.0, -1.0]]'),
            "on the edge",
            {},
        ),
        "hfield_refinement 'x'": (
            base.format(
                analyses='["engine"]', preset="paper-single-peak", tables='[grid]\nhfield_refinement = "x"'
            ),
            "hfield_refinement",
            {},
        ),
        "4000 x refinement 2, both engines (300 MiB budget)": (
            base.format(
                analyses='["engine"]',
                preset="paper-single-peak",
                tables='[grid]\nengine = ["mujoco", "bullet"]\n'
                "hfield_resolution = 4000\nhfield_refinement = 2",
            ),
            "an hfield of 7999 x 7999 samples",
            {"SPINE_MJ_MEMORY_BUDGET": "300M"},
        ),
    }
    for name, (body, needle, env) in configs.items():
        if "{analyses}" in body:
            body = body.format(analyses='["engine"]', preset="paper-single-peak", tables="")
        cfg = sweep_config(work, "left-" + "".join(c if c.isalnum() else "-" for c in name), body)
        add(
            f"sweep: {name}",
            [*SPINE, "sweep", cfg, "--out", "s44b", "--workers", "1", "--quiet"],
            "refuse",
            needle,
            env,
        )
    made = [*SPINE, "surface", "make", "paper-fractal", "--set", "nx=2048", "-o", "f2048.npz"]
    subprocess.run(made, cwd=work, check=True, capture_output=True)
    add(
        "simulate --engine bullet on a 2048 x 2048 fractal (1767 a side after coarsening)",
        [*SPINE, "simulate", "f2048.npz", "--engine", "bullet", "--start", "0.1,0.5", "--out", "bf"],
        "refuse",
        "1767 x 1767 samples is more than pybullet takes",
    )
    add(
        "hold --fill zero",
        [*SPINE, "hold", "paper-fractal", "--fill", "zero", "--out", "h"],
        "refuse",
        "--fill",
    )


def run_probe(work, name, args, expect, needle, env):
    before = {p for p in work.rglob("*")}
    try:
        proc = subprocess.run(
            args, cwd=work, capture_output=True, text=True, timeout=120, env={**os.environ, **env}
        )
    except subprocess.TimeoutExpired:
        return False, "timed out after 120 s"
    text = (proc.stdout + proc.stderr).replace("\r", "\n")
    lines = [ln for ln in text.splitlines() if ln.strip() and "%|" not in ln]
    if expect == "ok":
        good = proc.returncode == 0 and needle in text
        return good, f"exit {proc.returncode}" + ("" if good else f": {lines[-1:]}")
    new = sorted(str(p.relative_to(work)) for p in set(work.rglob("*")) - before)
    good = (
        proc.returncode == 2
        and len(lines) == 1
        and lines[0].startswith("Error:")
        and needle in lines[0]
        and not new
    )
    detail = lines[0] if len(lines) == 1 else f"{len(lines)} lines: {lines[:3]}"
    return good, f"exit {proc.returncode}, {detail}" + (f", wrote {new}" if new else "")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--novideo", help="bin/ folder of an environment without the video extra")
    ap.add_argument(
        "--only",
        action="append",
        metavar="TEXT",
        help="run only the probes whose name holds TEXT (repeatable; the set-up still runs, and a "
        "probe that reads an earlier probe's output needs that one selected too)",
    )
    args = ap.parse_args(argv)
    work = Path(tempfile.mkdtemp(prefix="spine-mj-probes-"))
    try:
        results = []
        for name, cmd, expect, needle, env in probes(work, args.novideo):
            if args.only and not any(text in name for text in args.only):
                continue
            good, detail = run_probe(work, name, cmd, expect, needle, env)
            results.append(good)
            print(f"{'PASS' if good else 'FAIL'}  {name}: {detail}", flush=True)
        print(f"{sum(results)} of {len(results)} probes end as they must")
        return 0 if all(results) else 1
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    raise SystemExit(main())

"""Do the committed quick-plan numbers reproduce on this machine? Put a new run's headline
numbers beside the committed 95 % intervals (spine_mj.validate.headlines).

    # on another CPU: run the quick plan there, then
    python analysis/reproduction_check.py demo-out/validation.json

    # on this CPU with the vector code paths of an older one (x86-64-v2: no AVX2, FMA or
    # AVX-512 in numpy, the C library's maths, OpenBLAS or numba), the quick plan run and checked
    python analysis/reproduction_check.py --emulate-x86-64-v2 --out emulated-out

Writes a Markdown table (``-o``, default: printed) and exits 1 when a number lies outside
its committed interval or a family's verdict changed.

What differs between two x86-64 CPUs is the code paths picked by CPU: numpy's dispatch
(NPY_DISABLE_CPU_FEATURES), glibc's maths (GLIBC_TUNABLES), OpenBLAS's kernels behind numpy's
and scipy's matrix products (OPENBLAS_CORETYPE) and the machine code numba generates for the
host (NUMBA_CPU_NAME); the emulation switches all four to x86-64-v2 (OpenBLAS to Nehalem). On
an AVX-512 machine numpy's and glibc's exp, log, power and trigonometric results then
differ in the last bits, as another CPU's do. MuJoCo's wheel carries one AVX build without
run-time dispatch (no cpuid, no AVX-512 instruction in libmujoco 4.0.0), so its own
arithmetic is the same on every AVX machine and differs only through glibc's maths. Another
architecture (ARM) or MuJoCo build is not covered: that needs the other machine.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from spine_mj.atomic import atomic_output
from spine_mj.errors import OneLineParser, SpineInputError
from spine_mj.validate.headlines import check_reproduction, headline_numbers

REPO = Path(__file__).resolve().parents[1]
COMMITTED = REPO / "analysis" / "reports" / "validation-quick" / "validation.json"

#: What an x86-64-v2 CPU gives numpy's dispatch and glibc's maths (Linux, glibc >= 2.33).
X86_64_V2 = {
    "NPY_DISABLE_CPU_FEATURES": "X86_V3 X86_V4 AVX512_ICL AVX512_SPR",
    "GLIBC_TUNABLES": "glibc.cpu.hwcaps=-AVX2,-FMA,-AVX512F,-AVX512DQ,-AVX512VL,-AVX512BW",
    "NUMBA_CPU_NAME": "x86-64-v2",
    "OPENBLAS_CORETYPE": "Nehalem",
}


def _fmt(v) -> str:
    return "-" if v is None else f"{v:.4g}"


def table(rows) -> str:
    lines = [
        "| number | committed | 95 % interval | new | inside | verdict kept |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        ci = "-" if r.interval is None else f"[{_fmt(r.interval[0])}, {_fmt(r.interval[1])}]"
        lines.append(
            f"| {r.key} | {_fmt(r.committed)} | {ci} | {_fmt(r.new)} | "
            f"{'yes' if r.inside else '**no**'} | {'yes' if r.verdict_kept else '**no**'} |"
        )
    bad = sum(not r.ok for r in rows)
    lines.append("")
    lines.append(f"{len(rows) - bad} of {len(rows)} inside the committed intervals, verdicts kept.")
    return "\n".join(lines)


def _writable(path: Path) -> None:
    """Refuse, before any work, a report path that cannot be written."""
    if path.is_dir():
        raise SpineInputError(f"-o {path}: is a folder; give a file name")
    folder = path.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent  # atomic_output makes the missing folders
    blocked = not folder.is_dir() or not os.access(folder, os.W_OK)
    if blocked or (path.exists() and not os.access(path, os.W_OK)):
        raise SpineInputError(f"-o {path}: cannot write there ({folder} is not a writable folder)")


def main(argv=None) -> int:
    ap = OneLineParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("new", nargs="?", help="validation.json of the new run")
    ap.add_argument("--committed", default=str(COMMITTED), help="the committed validation.json")
    ap.add_argument(
        "--emulate-x86-64-v2", action="store_true", help="run the quick plan with x86-64-v2 code paths"
    )
    ap.add_argument("--out", default="emulated-out", help="output folder of the emulated run")
    ap.add_argument("-o", "--report", help="write the table here (Markdown)")
    args = ap.parse_args(argv)
    try:
        return _run(args)
    except SpineInputError as exc:
        print(f"Error: {exc}", file=sys.stderr)
        return 2


def _run(args) -> int:
    if args.report:
        _writable(Path(args.report))
    if args.emulate_x86_64_v2:
        env = {**os.environ, **X86_64_V2}
        spine = str(Path(sys.executable).with_name("spine-mj"))
        subprocess.run([spine, "validate", "--quick", "--out", args.out], env=env, check=True)
        new = Path(args.out) / "validation.json"
    elif args.new:
        new = Path(args.new)
    else:
        raise SpineInputError("give the new run's validation.json, or --emulate-x86-64-v2 (see --help)")
    docs = []
    for path in (args.committed, new):
        try:
            docs.append(json.loads(Path(path).read_text()))
            headline_numbers(docs[-1])
        except (OSError, ValueError, SpineInputError) as exc:  # a missing or malformed file
            raise SpineInputError(f"{path}: {exc}") from None
        except RecursionError:
            raise SpineInputError(f"{path}: JSON nested too deep to read (not a validation.json)") from None
    committed, fresh = docs
    rows = check_reproduction(fresh, committed)
    text = f"New: {fresh.get('platform')}\n\nCommitted: {committed.get('platform')}\n\n"
    text += table(rows) + "\n"
    if args.report:
        try:
            with atomic_output(Path(args.report)) as tmp:
                tmp.write_text(text)
        except OSError as exc:
            raise SpineInputError(f"-o {args.report}: cannot write it ({exc.strerror})") from None
    print(text)
    return 0 if all(r.ok for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())

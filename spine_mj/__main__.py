"""``python -m spine_mj``: the ``spine-mj`` program (as ``python -m spine_mj.cli``)."""

from spine_mj.cli import run

if __name__ == "__main__":  # pragma: no cover
    run()

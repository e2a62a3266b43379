"""``python -m spine_mj.cli``: the ``spine-mj`` program."""

from spine_mj.cli import run

if __name__ == "__main__":  # pragma: no cover
    run()

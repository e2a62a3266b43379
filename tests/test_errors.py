"""Atomic output: all or nothing, with ordinary file permissions."""

import os
import re
import stat

import pytest

from spine_mj.atomic import all_or_none, atomic_output, writable_path
from spine_mj.errors import SpineInputError, check_count


def test_atomic_output_writes_on_success_with_umask_permissions(tmp_path):
    old = os.umask(0o022)
    try:
        with atomic_output(tmp_path / "sub" / "a.txt") as tmp:
            tmp.write_text("hello")
    finally:
        os.umask(old)
    path = tmp_path / "sub" / "a.txt"
    assert path.read_text() == "hello"
    assert stat.S_IMODE(path.stat().st_mode) == 0o644
    assert sorted(p.name for p in path.parent.iterdir()) == ["a.txt"]


def test_atomic_output_leaves_nothing_on_failure(tmp_path):
    with pytest.raises(RuntimeError), atomic_output(tmp_path / "b.txt") as tmp:
        tmp.write_text("half")
        raise RuntimeError("boom")
    assert list(tmp_path.iterdir()) == []


def test_all_or_none_restores_what_existed_and_removes_what_it_made(tmp_path):
    kept, made = tmp_path / "kept.txt", tmp_path / "made.txt"
    kept.write_text("old")
    with pytest.raises(RuntimeError), all_or_none(kept, made, None):
        with atomic_output(kept) as tmp:
            tmp.write_text("new")
        with atomic_output(made) as tmp:
            tmp.write_text("new")
        raise RuntimeError("the third output failed")
    assert kept.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kept.txt"]


def test_all_or_none_removes_the_folders_it_made_for_outputs_that_failed(tmp_path):
    out = tmp_path / "runs" / "one"
    with pytest.raises(RuntimeError), all_or_none(out / "a.txt", out / "sub" / "b.txt"):
        (out / "a.txt").write_text("new")
        raise RuntimeError("the second output failed")
    assert list(tmp_path.iterdir()) == []

    (tmp_path / "mine").mkdir()
    with pytest.raises(RuntimeError), all_or_none(tmp_path / "mine" / "a.txt"):
        raise RuntimeError("failed")
    assert (tmp_path / "mine").is_dir(), "a folder that was there stays"


def test_all_or_none_keeps_every_output_on_success(tmp_path):
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    a.write_text("old")
    with all_or_none(a, b):
        a.write_text("new a")
        b.write_text("new b")
    assert (a.read_text(), b.read_text()) == ("new a", "new b")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "b.txt"]


def test_an_unwritable_path_is_refused_before_any_work(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(SpineInputError, match="file is a file, not a folder"):
        writable_path(tmp_path / "file" / "out.txt")
    with pytest.raises(SpineInputError, match="it is a folder"):
        writable_path(tmp_path)


def test_a_full_disk_names_the_file_being_written(tmp_path):
    """pyarrow and numpy raise ENOSPC without a file name: the error names the output."""
    import errno

    dest = tmp_path / "runs.parquet"
    with pytest.raises(SpineInputError, match=r"cannot write .*runs\.parquet: No space left on device"):
        with atomic_output(dest):
            raise OSError(errno.ENOSPC, "No space left on device")
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(FileNotFoundError):  # an error that names its own file is left as it is
        with atomic_output(dest):
            open(tmp_path / "missing.txt")


def test_remove_temporaries_removes_what_a_killed_writer_left_and_nothing_else(tmp_path):
    from spine_mj.atomic import remove_temporaries

    figures = tmp_path / "figures"
    figures.mkdir()
    left = [figures / ".boundary.png.k3x_9q2a.png", tmp_path / ".validation.json.abcdefgh.json"]
    left.append(tmp_path / ".report.md.4242.keep")
    kept = [figures / "boundary.png", figures / ".hidden", tmp_path / ".notes.txt.abcdefgh.png"]
    for p in left + kept:
        p.write_text("x")
    assert sorted(remove_temporaries(tmp_path)) == sorted(left)
    assert all(p.exists() for p in kept) and not any(p.exists() for p in left)


def test_atomic_output_temporaries_are_what_remove_temporaries_removes(tmp_path):
    """A writer killed inside the block leaves its temporary; the pattern must know its name."""
    from spine_mj.atomic import remove_temporaries

    dest = tmp_path / "fig.png"
    writer = atomic_output(dest)  # entered and never left, as in a killed process
    tmp = writer.__enter__()
    assert tmp.exists()
    assert remove_temporaries(tmp_path) == [tmp]


@pytest.mark.parametrize("value", ["3", 2.5, float("nan"), float("inf"), True, None, 0, 11, [3]])
def test_check_count_refuses_what_is_no_whole_number_in_range_in_one_named_line(value):
    with pytest.raises(
        SpineInputError, match=rf"^n must be a whole number in \[1, 10\], got {re.escape(repr(value))}$"
    ):
        check_count("n", value, most=10)


def test_check_count_takes_integers_and_whole_floats_of_any_kind():
    import numpy as np

    assert [check_count("n", v) for v in (3, 3.0, np.int64(3), np.float32(3.0))] == [3, 3, 3, 3]
    with pytest.raises(SpineInputError, match=r"n must be a whole number >= 1, got (np\.)?True"):
        check_count("n", np.bool_(True))

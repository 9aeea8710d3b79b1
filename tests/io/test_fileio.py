"""Atomic writes: a temporary file renamed onto a regular target; a device or a FIFO written in place."""

import os
import stat
import threading

from ipmc_asym.io.fileio import atomic_write


def test_a_fifo_target_is_written_in_place_not_replaced(tmp_path):
    """A rename onto a device or a FIFO would replace it with a regular file (run as root onto
    /dev/null, it replaced the machine's /dev/null): such a target is written in place. A FIFO
    stands for the devices here, so that a failing run harms nothing."""
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    got = []

    def read():
        with open(fifo, encoding="utf-8") as fh:
            got.append(fh.read())

    reader = threading.Thread(target=read)
    reader.start()
    with atomic_write(fifo) as fh:
        fh.write("a,b\n1,2\n")
    reader.join(timeout=30)
    assert got == ["a,b\n1,2\n"]
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    assert sorted(os.listdir(tmp_path)) == ["pipe"]  # no temporary file left beside it


def test_a_regular_target_is_replaced_whole(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("old\n")
    with atomic_write(target) as fh:
        fh.write("new\n")
    assert target.read_text() == "new\n" and sorted(os.listdir(tmp_path)) == ["out.csv"]

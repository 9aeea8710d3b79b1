"""Input files through one bounded reader (``base.inputs``): non-regular files refused before a
read, sizes capped (``--max-input-size``), for every command that reads a file."""

from __future__ import annotations

import os

import pytest
from references import REPO

from ipmc_asym.base.inputs import input_size_cap, parse_size, read_input_bytes
from ipmc_asym.cli import main

EXAMPLES = REPO / "examples"


def test_dev_zero_and_fifo_refused_without_reading(tmp_path):
    with pytest.raises(ValueError, match="not a regular file"):
        read_input_bytes("/dev/zero", "scene file")
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(ValueError, match="not a regular file"):  # and no blocking on open
        read_input_bytes(fifo)
    with pytest.raises(ValueError, match="is a directory"):
        read_input_bytes(tmp_path)


def test_cap_counts_bytes(tmp_path):
    f = tmp_path / "x.toml"
    f.write_bytes(b"a" * 1000)
    with input_size_cap(1000):
        assert len(read_input_bytes(f)) == 1000
    with input_size_cap(999), pytest.raises(ValueError, match="1000 bytes, more than the cap 999"):
        read_input_bytes(f)


@pytest.mark.parametrize("text, n", [("64MB", 64 * 10**6), ("1GiB", 2**30), ("5e6", 5 * 10**6), ("10 kB", 10**4)])
def test_parse_size(text, n):
    assert parse_size(text) == n


@pytest.mark.parametrize("text", ["0", "-1", "x", "1XB", "nan", "1e30"])
def test_parse_size_refused(text):
    with pytest.raises(ValueError, match="--max-input-size must be a size"):
        parse_size(text)


@pytest.mark.parametrize("argv", [
    ["scene", "/dev/zero"], ["uq", "/dev/zero"], ["design", "/dev/zero"],
    ["fit", "/dev/zero", "--free", "modulus"],
    ["scene", "FIFO"],
    ["drive", "--waveform", "csv:/dev/zero", "--duration", "1s"],
])
def test_commands_refuse_non_regular_inputs(argv, capsys, tmp_path):
    # a FIFO made here (it stands for a device: a test must not write to the machine's /dev/null)
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    argv = [str(fifo) if a == "FIFO" else a for a in argv]
    try:
        rc = main(argv)
    except SystemExit as exc:  # refused while parsing (argparse)
        rc = exc.code
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "not a regular file" in err, err


def test_max_input_size_option(tmp_path, capsys):
    scene = EXAMPLES / "uq_nominal.toml"
    size = scene.stat().st_size
    rc = main(["scene", str(scene), "--max-input-size", str(size - 1)])
    err = capsys.readouterr().err
    assert rc == 2 and f"more than the cap {size - 1}" in err and err.count("\n") == 1, err
    assert main(["scene", str(scene), "--max-input-size", "1MB", "--json"]) == 0


def test_fit_csv_huge_field_names_the_line(tmp_path, capsys):
    f = tmp_path / "d.csv"
    f.write_text("voltage,deflection\n1V,1mm\n2V," + '"' + "1" * (5 * 2**20) + '"\n')
    rc = main(["fit", str(f), "--free", "modulus"])
    err = capsys.readouterr().err
    assert rc == 2 and "line 3" in err and "field larger than field limit" in err, err


def test_waveform_csv_huge_field_names_the_line(tmp_path):
    from ipmc_asym.dynamics.waveforms import parse_waveform

    f = tmp_path / "w.csv"
    f.write_text("t,V\n0,0\n1," + '"' + "1" * (5 * 2**20) + '"\n')
    with pytest.raises(ValueError, match="line 3: cannot read .field larger than field limit"):
        parse_waveform(f"csv:{f}")

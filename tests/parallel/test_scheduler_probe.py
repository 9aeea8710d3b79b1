"""``--scheduler tcp://HOST:PORT`` at a server that is not dask: one line, exit 2, in seconds.

Two local servers stand in for a wrong address: one answering like a web server (its reply read
as a dask length prefix would ask for exabytes) and one that accepts and stays silent (dask's
client would wait for its handshake); a closed port is refused too.
"""

from __future__ import annotations

import contextlib
import socket
import threading
import time

import pytest

from ipmc_asym.cli import main
from ipmc_asym.parallel import executors


@contextlib.contextmanager
def server(reply: bytes | None):
    """A TCP server on localhost sending ``reply`` to each client (None: silent); yields its address."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    srv.settimeout(0.2)
    stop = threading.Event()
    conns = []

    def serve():
        while not stop.is_set():
            try:
                c, _ = srv.accept()
            except OSError:
                continue
            conns.append(c)
            if reply is not None:
                with contextlib.suppress(OSError):
                    c.sendall(reply)

    th = threading.Thread(target=serve, daemon=True)
    th.start()
    try:
        yield f"tcp://127.0.0.1:{srv.getsockname()[1]}"
    finally:
        stop.set()
        th.join()
        for c in conns:
            c.close()
        srv.close()


@pytest.fixture
def short_probe(monkeypatch):
    monkeypatch.setattr(executors, "PROBE_TIMEOUT", 0.5)


def test_http_server_is_not_a_scheduler(short_probe):
    with server(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n") as addr:
        with pytest.raises(ValueError, match="not a dask scheduler"):
            executors.check_scheduler(addr)


def test_silent_server_times_out(short_probe):
    with server(None) as addr:
        t0 = time.monotonic()
        with pytest.raises(ValueError, match="no dask handshake within 0.5 s"):
            executors.check_scheduler(addr)
        assert time.monotonic() - t0 < 5.0  # bounded by the probe's timeout, not dask's retries


def test_closed_port_refused(short_probe):
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    with pytest.raises(ValueError, match="cannot connect"):
        executors.check_scheduler(f"tcp://127.0.0.1:{port}")


def test_a_dask_length_prefix_passes(short_probe):
    # a dask comm's first message: its length (little-endian u64), then the msgpack frames
    with server((312).to_bytes(8, "little") + b"\x00" * 312) as addr:
        assert executors.check_scheduler(addr) == addr


@pytest.mark.parametrize("reply", [b"SSH-2.0-OpenSSH_9.6\r\n", None])
def test_cli_sweep_one_line_exit_2(short_probe, reply, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with server(reply) as addr:
        rc = main(["sweep", "--vary", "voltage=0.5V:1V:3", "--scheduler", addr, "--no-progress"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "--scheduler" in err and "Traceback" not in err, err

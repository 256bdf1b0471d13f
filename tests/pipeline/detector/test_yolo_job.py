"""The detector job's guard against the network (synthua_usd/pipeline/detector/yolo_job.py imports only the standard
library at its top, so it loads here without Ultralytics): lookups and internet connections are refused and listed,
local sockets keep working. That Ultralytics tries nothing during a real job is checked in test_sim2real.py."""

from __future__ import annotations

import socket

import pytest

from synthua_usd.pipeline.detector import yolo_job


@pytest.fixture
def guarded(monkeypatch):
    # monkeypatch puts the real functions back after the test
    monkeypatch.setattr(socket, "getaddrinfo", socket.getaddrinfo)
    monkeypatch.setattr(socket.socket, "connect", socket.socket.connect)
    return yolo_job.refuse_network()


def test_lookups_and_internet_connections_are_refused_and_listed(guarded):
    with pytest.raises(socket.gaierror, match="network refused by synthua's detector job"):
        socket.getaddrinfo("github.com", 443)
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s, pytest.raises(OSError, match="connect to 127.0.0.1"):
        s.connect(("127.0.0.1", 9))
    assert guarded == [{"call": "getaddrinfo", "host": "github.com"}, {"call": "connect", "host": "127.0.0.1"}]


def test_local_sockets_still_work(guarded, tmp_path):
    """A data loader's workers share tensors over Unix sockets: those connect as before."""
    address = str(tmp_path / "s")
    with socket.socket(socket.AF_UNIX) as server, socket.socket(socket.AF_UNIX) as client:
        server.bind(address)
        server.listen(1)
        client.connect(address)
        peer, _ = server.accept()
        with peer:
            client.sendall(b"ok")
            assert peer.recv(2) == b"ok"
    assert guarded == []

"""Connecting to a Ray cluster: an address where nothing answers fails at once, and what Ray's C++ core
prints on file descriptor 2 meanwhile goes with the error (to RUN/error.log), not to the terminal."""

import os
import socket

import pytest

ray = pytest.importorskip("ray", reason="ray is not installed (pip install 'shaped-es[ray]')")

from shaped_es.executors import ExecutorError  # noqa: E402
from shaped_es.executors import ray_executor  # noqa: E402

GCS_LINE = b"[2026-01-01 00:00:00,000 W 1 1] gcs_client.cc:210: Failed to get cluster ID from GCS server\n"


def _closed_port() -> int:
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()  # nothing listens there now
    return port


def test_an_address_where_nothing_answers_fails_at_once(monkeypatch):
    monkeypatch.setattr(ray, "init", lambda **kw: pytest.fail("ray.init must not be tried"))
    address = f"127.0.0.1:{_closed_port()}"
    with pytest.raises(ExecutorError, match=f"cannot connect to Ray at '{address}': nothing answers there"):
        ray_executor._connect(address)


def test_rays_own_output_goes_with_the_error_not_to_the_terminal(monkeypatch, capfd):
    def failing_init(**kw):
        for _ in range(20):
            os.write(2, GCS_LINE)  # as Ray's C++ core does, below Python's sys.stderr
        raise ConnectionError("Failed to connect to Ray cluster at 10.0.0.1:6379")

    monkeypatch.setattr(ray, "init", failing_init)
    monkeypatch.setattr(ray_executor, "_check_answers", lambda address: None)  # something answers there
    with pytest.raises(ExecutorError) as e:
        ray_executor._connect("10.0.0.1:6379")
    assert str(e.value) == ("cannot connect to Ray at '10.0.0.1:6379': Failed to connect to Ray cluster at "
                            "10.0.0.1:6379")
    assert e.value.detail.count("gcs_client.cc") == 20
    assert capfd.readouterr().err == ""


def test_rays_output_on_a_connection_that_works_becomes_one_warning(monkeypatch, capfd):
    monkeypatch.setattr(ray, "init", lambda **kw: os.write(2, GCS_LINE))
    monkeypatch.setattr(ray_executor, "_check_answers", lambda address: None)
    with pytest.warns(UserWarning, match="Ray's output while connecting: .*gcs_client.cc"):
        ray_executor._connect("10.0.0.1:6379")
    assert capfd.readouterr().err == ""

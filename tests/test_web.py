"""The live display server: API, WebSocket replay and controls, disconnects, growing runs, path safety."""

from __future__ import annotations

import base64
import json
import os
import warnings

import cv2
import numpy as np
import pytest
from fastapi.testclient import TestClient

from cli_helpers import assert_one_line_error as _assert_one_line_error
from skyradar.daa.pipeline import alerts_from_tracks, ownship_from_frames, truth_tracks
from skyradar.errors import InputError
from skyradar.io.frames import FrameStoreWriter
from skyradar.io.tables import write_table
from skyradar.web.sample import sample_run_dataset, write_sample_run
from skyradar.web.server import create_app, serve_in_thread

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning", "ignore::UserWarning")

# Sample run: head-on intruder (target 0) enters radar range (5 km) at 15 s; loss of well clear
# (2200 ft) at (6500 - 670.56) / 100 = 58.29 s, so the raw warning (25 s) starts at frame 34 and
# the 2-of-4 issued warning at 35 s.
WARNING_AT_S = 35.0


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return write_sample_run(tmp_path_factory.mktemp("web") / "run.zarr")


@pytest.fixture(scope="module")
def client(run):
    with TestClient(create_app(run, speed=50.0, autoplay=False)) as c:
        yield c


def _frames_until(ws, pred, limit=200):
    for _ in range(limit):
        msg = ws.receive_json()
        if pred(msg):
            return msg
    raise AssertionError("expected message not received")


def test_page_and_static(client):
    page = client.get("/")
    assert page.status_code == 200 and 'id="plan"' in page.text
    js = client.get("/static/app.js")
    assert js.status_code == 200 and "WebSocket" in js.text


def test_info_and_frame_payload(client):
    info = client.get("/api/info").json()
    assert info["n_ready"] == 60 and not info["growing"] and info["traffic_source"] == "truth"
    early = client.get("/api/frame/10?image=false").json()
    assert [t["track_id"] for t in early["traffic"]] == [1] and early[
        "max_level"
    ] == 0  # head-on not in range
    f = client.get("/api/frame/40").json()
    head_on = next(t for t in f["traffic"] if t["track_id"] == 0)
    assert head_on["level"] == 3 and head_on["sector"] == 0
    assert head_on["range_m"] == pytest.approx(6500 - 100 * 40)
    crossing = next(t for t in f["traffic"] if t["track_id"] == 1)
    assert crossing["level"] == 0 and crossing["rel_alt_m"] == pytest.approx(400.0)
    assert f["advice"]["preferred_heading_deg"] is not None
    # The image shows the head-on intruder at its range and closing speed (range grows upwards).
    png = base64.b64decode(f["rd_png"].split(",", 1)[1])
    img = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_GRAYSCALE)
    ds = sample_run_dataset(n_frames=41)
    r = round(2500 / ds["range"].values[1])
    # Closing at 100 m/s aliases once: -100 + 2 VLim = -21.7 m/s.
    d = int(np.argmin(np.abs(ds["doppler"].values - (-100.0 + 2 * 39.16))))
    assert img[img.shape[0] - 1 - r, d] == img.max() > img[img.shape[0] - 1 - r, (d + 5) % img.shape[1]]
    assert client.get("/api/frame/60").status_code == 404


def test_websocket_seek_speed_and_play(client):
    with client.websocket_connect("/ws") as ws:
        info = ws.receive_json()
        assert info["type"] == "info" and info["playing"] is False
        assert ws.receive_json()["index"] == 0
        ws.send_json({"cmd": "seek", "time_s": WARNING_AT_S - 1})
        before = ws.receive_json()
        assert before["index"] == 34 and before["max_level"] == 2
        ws.send_json({"cmd": "seek", "index": 35})
        assert ws.receive_json()["max_level"] == 3
        ws.send_json({"cmd": "speed", "value": 100})
        ws.send_json({"cmd": "play"})
        indices = [ws.receive_json()["index"] for _ in range(5)]
        assert indices == [36, 37, 38, 39, 40]
        ws.send_json({"cmd": "seek", "index": 57})
        msg = _frames_until(ws, lambda m: m["type"] == "end")
        assert msg["index"] == 59
        ws.send_text("not json")  # ignored
        ws.send_json({"cmd": "seek", "index": 1})
        assert ws.receive_json()["index"] == 1


def test_client_disconnect_mid_stream(run):
    app = create_app(run, speed=100.0)
    with TestClient(app) as c:
        for _ in range(3):
            with c.websocket_connect("/ws") as ws:
                ws.receive_json()
                ws.receive_json()
                ws.receive_json()
            # leaving the block closes the socket while the server is streaming
        with c.websocket_connect("/ws") as ws:
            assert ws.receive_json()["type"] == "info"
            assert ws.receive_json()["type"] == "frame"
        assert c.get("/api/info").status_code == 200


def test_growing_cint16_run_is_shown_decoded(tmp_path):
    # A cint16 store holds int16 codes and scales, no `iq`: the display must decode it while growing.
    ds = sample_run_dataset(n_frames=20)
    template = ds.assign(iq=ds["iq"].chunk({"time": 10}))
    writer = FrameStoreWriter(tmp_path / "live.zarr", template, 10, fingerprint="t", precision="cint16")
    writer.write_chunk(0, ds["iq"].values[0:10])
    with TestClient(create_app(tmp_path / "live.zarr", speed=100.0)) as c:
        info = c.get("/api/info").json()
        assert info["growing"] and info["n_ready"] == 10 and info["n_total"] == 20
        frame = c.get("/api/frame/9").json()
        assert frame["index"] == 9 and frame["rd_png"].startswith("data:image/png")
        assert c.get("/api/frame/10").status_code == 404


def test_growing_run_is_followed_until_renamed(tmp_path):
    ds = sample_run_dataset(n_frames=30)
    template = ds.assign(iq=ds["iq"].chunk({"time": 10}))
    final = tmp_path / "live.zarr"
    writer = FrameStoreWriter(final, template, 10, fingerprint="t")
    writer.write_chunk(0, ds["iq"].values[0:10])
    app = create_app(final, speed=100.0)
    with TestClient(app) as c:
        info = c.get("/api/info").json()
        assert info["growing"] and info["n_ready"] == 10 and info["n_total"] == 30
        assert c.get("/api/frame/10").status_code == 404
        with c.websocket_connect("/ws") as ws:
            assert ws.receive_json()["growing"] is True
            seen = [ws.receive_json()["index"] for _ in range(10)]
            assert seen == list(range(10))
            writer.write_chunk(1, ds["iq"].values[10:20])
            assert ws.receive_json()["index"] == 10  # the server polls the done marks
            writer.write_chunk(2, ds["iq"].values[20:30])
            writer.close()  # rename .partial -> final while streaming
            msgs = [ws.receive_json() for _ in range(20)]
        assert [m["index"] for m in msgs[:19]] == list(range(11, 30))
        assert msgs[19]["type"] == "end"
        last = c.get("/api/frame/29").json()
        assert not c.get("/api/info").json()["growing"]
        assert last["traffic"][0]["range_m"] == pytest.approx(6500 - 100 * 29)
        # The last frame has its pixel (read from the renamed store, not zeros).
        png = base64.b64decode(last["rd_png"].split(",", 1)[1])
        img = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_GRAYSCALE)
        assert img.max() > 3 * np.median(img)  # 20 dB pixel over the empty (floor) background


def test_missing_run_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="no such run"):
        create_app(tmp_path / "nothing.zarr")


def test_alerts_table_is_displayed(run, tmp_path):
    import xarray as xr

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = xr.open_zarr(run)
    alerts = alerts_from_tracks(truth_tracks(ds), ownship_from_frames(ds))
    alerts = alerts[alerts["track_id"] == 0]
    path = write_table(alerts, tmp_path / "alerts.parquet")
    with TestClient(create_app(run, alerts_path=path, autoplay=False)) as c:
        assert c.get("/api/info").json()["traffic_source"] == "alerts"
        f = c.get("/api/frame/50?image=false").json()
        assert [t["track_id"] for t in f["traffic"]] == [0]
        assert f["advice"]["heading_bands_deg"]


def test_rejects_paths_outside_the_run(tmp_path):
    served = tmp_path / "served"
    run = write_sample_run(served / "run.zarr", n_frames=3)
    table = write_table(truth_tracks(sample_run_dataset(n_frames=3)), served / "tracks.parquet")
    (served / "report.txt").write_text("sibling")  # next to the run but not given: not served
    secret = tmp_path / "secret.txt"
    secret.write_text("TOP-SECRET")
    os.symlink(secret, served / "link.txt")
    with TestClient(create_app(run, tracks_path=table)) as c:
        ok = c.get("/files/tracks.parquet")
        assert ok.status_code == 200 and ok.content == table.read_bytes()
        attempts = [
            "/files/report.txt",
            "/files/%2e%2e/served/tracks.parquet",
            "/files/%2Ftracks.parquet",
            "/files/..%2Fsecret.txt",
            "/files/%2e%2e/secret.txt",
            "/files/..%5Csecret.txt",
            "/files/%2Fetc%2Fpasswd",
            "/files//etc/passwd",
            "/files/link.txt",
            "/files/run.zarr/..%2F..%2Fsecret.txt",
            "/static/..%2F..%2Fweb%2Fserver.py",
            "/static/%2e%2e/server.py",
            "/files/report.txt%00.png",
        ]
        for url in attempts:
            r = c.get(url)
            assert r.status_code in (403, 404), url
            assert "TOP-SECRET" not in r.text and "def create_app" not in r.text and "root:" not in r.text


def test_real_server_survives_abrupt_disconnects(run):
    """Over real TCP (uvicorn + websockets): clients that vanish mid-stream do not stop the server."""
    import httpx
    from websockets.sync.client import connect

    with serve_in_thread(create_app(run, speed=100.0)) as url:
        ws_url = url.replace("http", "ws") + "/ws"
        for _ in range(3):
            with connect(ws_url, open_timeout=10) as ws:
                json.loads(ws.recv(timeout=10))
                json.loads(ws.recv(timeout=10))
                ws.socket.close()  # drop the TCP connection without a close handshake
        with connect(ws_url, open_timeout=10) as ws:
            assert json.loads(ws.recv(timeout=10))["type"] == "info"
            assert json.loads(ws.recv(timeout=10))["index"] == 0
        assert httpx.get(url + "/api/info", timeout=10).json()["n_ready"] == 60


@pytest.mark.slow
def test_cli_serve_runs_and_rejects_missing_run(run, tmp_path):
    import socket
    import subprocess
    import sys
    import time

    import httpx

    entry = [sys.executable, "-c", "from skyradar.cli import main; main()", "serve"]
    bad = subprocess.run(entry + [str(tmp_path / "none.zarr")], capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and bad.stderr.startswith("error:") and "no such run" in bad.stderr
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    proc = subprocess.Popen(
        entry + [str(run), "--port", str(port)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
    )
    try:
        deadline, info = time.monotonic() + 60, None
        while info is None and time.monotonic() < deadline and proc.poll() is None:
            try:
                info = httpx.get(f"http://127.0.0.1:{port}/api/info", timeout=2).json()
            except httpx.HTTPError:
                time.sleep(0.2)
        assert info is not None and info["n_ready"] == 60
        # Bound to loopback: a request addressed to another name (DNS rebinding) is refused.
        base = f"http://127.0.0.1:{port}/api/info"
        assert httpx.get(base, headers={"host": f"attacker.example:{port}"}, timeout=5).status_code == 403
        assert httpx.get(base, headers={"host": f"localhost:{port}"}, timeout=5).status_code == 200
    finally:
        proc.terminate()
        _, err = proc.communicate(timeout=20)
    assert "warning" not in err.decode()  # the default host is loopback


# --- Safe by default: served files, origin, command queue, hostile commands, CLI checks.


def _serve(*args, timeout=120):
    import subprocess
    import sys

    cmd = [sys.executable, "-m", "skyradar", "serve", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)


def _listening_port():
    """A socket listening on a free 127.0.0.1 port (the caller closes it)."""
    import socket

    sock = socket.socket()
    sock.bind(("127.0.0.1", 0))
    sock.listen()
    return sock, sock.getsockname()[1]


def test_files_serves_only_the_tables_given(tmp_path):
    """A run in a home folder: its neighbours (``.ssh/``, other files) are not served, only the tables."""
    home = tmp_path / "home"
    run = write_sample_run(home / "run.zarr", n_frames=3)
    (home / ".ssh").mkdir()
    (home / ".ssh" / "id_ed25519").write_text("PRIVATE-KEY")
    (home / "notes.txt").write_text("PRIVATE-NOTES")
    import xarray as xr

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = xr.open_zarr(run)
    table = alerts_from_tracks(truth_tracks(ds), ownship_from_frames(ds))
    alerts = write_table(table, home / "alerts.parquet")
    with TestClient(create_app(run, alerts_path=alerts)) as c:
        ok = c.get("/files/alerts.parquet")
        assert ok.status_code == 200 and ok.content == alerts.read_bytes()
        for url in ["/files/.ssh/id_ed25519", "/files/notes.txt", "/files/run.zarr/zarr.json", "/files/"]:
            r = c.get(url)
            assert r.status_code in (403, 404), url
            assert "PRIVATE" not in r.text
    with TestClient(create_app(run)) as c:  # no tables given: nothing is served under /files
        assert c.get("/files/alerts.parquet").status_code == 404


def test_websocket_rejects_foreign_origin(client):
    from starlette.websockets import WebSocketDisconnect

    for origin in ["http://evil.example", "http://testserver.evil.example", "http://localhost:9999", "null"]:
        with (
            pytest.raises(WebSocketDisconnect) as exc,
            client.websocket_connect("/ws", headers={"origin": origin}),
        ):
            pass
        assert exc.value.code == 1008, origin
    with client.websocket_connect("/ws", headers={"origin": "http://testserver"}) as ws:
        assert ws.receive_json()["type"] == "info"


def test_real_server_checks_origin_against_its_host(run):
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    with serve_in_thread(create_app(run, autoplay=False)) as url:
        ws_url, port = url.replace("http", "ws") + "/ws", url.rsplit(":", 1)[1]
        for origin in [url, f"http://localhost:{port}"]:
            with connect(ws_url, open_timeout=10, origin=origin) as ws:
                assert json.loads(ws.recv(timeout=10))["type"] == "info"
        with pytest.raises(InvalidStatus):
            connect(ws_url, open_timeout=10, origin="https://evil.example")


def test_command_queue_is_bounded():
    """A client flooding commands fills at most COMMAND_QUEUE_SIZE slots; the newest commands are kept."""
    import asyncio

    from starlette.websockets import WebSocketDisconnect

    from skyradar.web.server import COMMAND_QUEUE_SIZE, _read_commands

    n = 20 * COMMAND_QUEUE_SIZE

    class Flood:
        sent = 0

        async def receive_text(self):
            if self.sent == n:
                raise WebSocketDisconnect(1000)
            self.sent += 1
            return json.dumps({"cmd": "seek", "index": self.sent})

    async def main():
        queue = asyncio.Queue(maxsize=COMMAND_QUEUE_SIZE)
        # The guard only turns a blocked reader (an old-style `await queue.put`) into a failure.
        await asyncio.wait_for(_read_commands(Flood(), queue), timeout=30)
        return [queue.get_nowait() for _ in range(queue.qsize())]

    items = asyncio.run(main())
    assert len(items) <= COMMAND_QUEUE_SIZE
    assert items[-1] is None  # the disconnect is never dropped
    assert items[-2] == {"cmd": "seek", "index": n}  # the newest command survives


def test_websocket_survives_hostile_commands(run):
    """Over real TCP: numbers out of range, wrong types, deep or huge JSON are ignored or clamped."""
    from websockets.sync.client import connect

    def recv(ws):
        return json.loads(ws.recv(timeout=20))  # the timeout only guards against a hang

    server = serve_in_thread(create_app(run, autoplay=False))
    with server as url, connect(url.replace("http", "ws") + "/ws", open_timeout=10, max_size=None) as ws:
        assert recv(ws)["type"] == "info"
        assert recv(ws)["index"] == 0
        ws.send(json.dumps({"cmd": "speed", "value": 4}))
        ws.send(json.dumps({"cmd": "seek", "index": 3}))  # frames carry the replay state
        assert recv(ws)["speed"] == 4.0
        hostile = [
            '{"cmd": "seek", "index": 1e999}',
            '{"cmd": "seek", "index": -1e999}',
            '{"cmd": "seek", "index": NaN}',
            '{"cmd": "seek", "time_s": NaN}',
            '{"cmd": "seek", "time_s": -Infinity}',
            '{"cmd": "seek", "index": "abc"}',
            '{"cmd": "seek", "index": [1]}',
            '{"cmd": "seek", "index": true}',
            '{"cmd": "speed", "value": NaN}',
            '{"cmd": "speed", "value": "fast"}',
            '{"cmd": "speed", "value": -1e999}',
            '{"cmd": ["seek"]}',
            '{"cmd": "seek", "index": ' + "9" * 5000 + "}",  # int() refuses > 4300 digits
            "[" * 100_000,  # deeper than the JSON parser's recursion limit
            json.dumps({"cmd": "seek", "index": 1, "pad": "x" * 2_000_000}),
        ]
        for text in hostile:
            ws.send(text)
        ws.send(json.dumps({"cmd": "seek", "index": 7}))
        for _ in range(len(hostile) + 2):
            last = recv(ws)
            if last.get("index") == 7:
                break
        assert last["index"] == 7 and last["speed"] == 4.0 and last["playing"] is False
        ws.send(json.dumps({"cmd": "seek", "time_s": float("inf")}))  # sent as Infinity: the last frame
        assert recv(ws)["index"] == 59
        ws.send('{"cmd": "speed", "value": 1e999}')  # clamped to the fastest replay
        ws.send(json.dumps({"cmd": "seek", "index": 2}))
        assert recv(ws)["speed"] == 100.0


@pytest.mark.parametrize("speed", ["0", "-2", "nan"])
def test_cli_serve_rejects_bad_speed(run, speed):
    result = _serve(str(run), "--port", "0", "--speed", speed, timeout=60)
    _assert_one_line_error(result, "--speed", speed)


def test_cli_serve_port_taken_is_one_line(run):
    sock, port = _listening_port()
    with sock:
        result = _serve(str(run), "--port", str(port))
    _assert_one_line_error(result, f"127.0.0.1:{port}", "in use")


def test_cli_serve_warns_when_not_loopback(run, monkeypatch, capsys):
    """A server about to start on a non-loopback address warns (the server itself is not run here)."""
    import uvicorn

    from skyradar.cli.commands_daa import serve

    monkeypatch.setattr(uvicorn.Server, "run", lambda self, sockets=None: None)
    serve(run, port=0, host="0.0.0.0", tracks=None, alerts=None, speed=1.0)
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[0].startswith("warning: ") and "0.0.0.0" in lines[0]


def test_cli_serve_error_on_non_loopback_is_one_line(run):
    """A taken port on a non-loopback address is one line: no warning for a server that never starts."""
    sock, port = _listening_port()
    with sock:
        result = _serve(str(run), "--host", "0.0.0.0", "--port", str(port))
    lines = result.stderr.strip().splitlines()
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert len(lines) == 1 and lines[0].startswith("error: ") and f"0.0.0.0:{port}" in lines[0]


def test_loopback_and_origin_rules():
    from skyradar.web.net import is_loopback, origin_allowed

    assert is_loopback("127.0.0.1") and is_loopback("::1") and is_loopback("[::1]")
    assert not is_loopback("0.0.0.0") and not is_loopback("::") and not is_loopback("10.0.0.1")
    assert origin_allowed("http://[::1]:8765", "localhost:8765")
    assert origin_allowed("http://radar.local:8000", "radar.local:8000")
    assert not origin_allowed("http://localhost:8765", "radar.local:8765")  # page from elsewhere
    assert not origin_allowed("http://radar.local:8001", "radar.local:8000")
    assert not origin_allowed("file://", "127.0.0.1:8765") and not origin_allowed("http://x", None)


def test_serve_binds_loopback_by_default():
    import inspect

    from skyradar.cli.commands_daa import serve

    assert inspect.signature(serve).parameters["host"].default == "127.0.0.1"


def test_loopback_host_only_refuses_other_names(run):
    from starlette.websockets import WebSocketDisconnect

    from skyradar.web.net import LoopbackHostOnly

    with TestClient(LoopbackHostOnly(create_app(run, autoplay=False)), base_url="http://127.0.0.1:8765") as c:
        assert c.get("/api/info").status_code == 200
        assert c.get("/api/info", headers={"host": "attacker.example:8765"}).status_code == 403
        with c.websocket_connect("/ws", headers={"host": "localhost:8765"}) as ws:
            assert ws.receive_json()["type"] == "info"
        with (
            pytest.raises(WebSocketDisconnect) as exc,
            c.websocket_connect("/ws"),  # the test client's WebSocket host is "testserver"
        ):
            pass
        assert exc.value.code == 1008


def test_frame_without_height_above_ground_is_strict_json(tmp_path):
    """A clear-sky run has no height above the ground (NaN): the page gets null, never a bare NaN."""
    ds = sample_run_dataset(n_frames=3)
    ds["own_height_agl_m"] = ds["own_height_agl_m"] * np.nan
    writer = FrameStoreWriter(tmp_path / "run.zarr", ds, 3, fingerprint="clear-sky")
    writer.write_chunk(0, ds["iq"].values)
    run = writer.close()
    with TestClient(create_app(run, autoplay=False)) as client:
        response = client.get("/api/frame/1?image=false")
        assert response.status_code == 200
        assert response.json()["ownship"]["height_agl_m"] is None
        with client.websocket_connect("/ws") as ws:
            ws.receive_text()  # info
            json.loads(ws.receive_text(), parse_constant=_refuse)  # the first frame, as JSON.parse reads it


def _refuse(name: str):
    raise AssertionError(f"bare {name} in a WebSocket message")

"""Live traffic display: FastAPI app that replays a run over a WebSocket to a static page.

Endpoints
---------
``GET /``                 the page (``static/index.html``; no build step)
``GET /static/{path}``    the page's JS and CSS
``GET /files/{name}``     the tables given with ``tracks_path`` / ``alerts_path``, by file name (for
                          download); nothing else: not the run's folder, its neighbours or the store
``GET /api/info``         run summary (frame times, whether it is still being written)
``GET /api/frame/{i}``    one frame's payload as JSON (``?image=false`` leaves out the image)
``WS  /ws``               replay: the server sends ``info`` then ``frame`` messages at the run's
                          pace times the speed; the client sends ``{"cmd": "play"|"pause"}``,
                          ``{"cmd": "speed", "value": 4}``, ``{"cmd": "seek", "index": 12}`` or
                          ``{"cmd": "seek", "time_s": 30.5}``. At the end of a finished run the
                          server sends ``{"type": "end"}`` and pauses; a growing run is polled.
                          Frames carry the replay state (``playing``, ``speed``).

Safety: the page reads frames only through ``/api`` and ``/ws``, so ``/files`` serves only the
tables named when the app was built. ``/ws`` accepts only same-origin pages (see
:func:`skyradar.web.net.origin_allowed`; others are closed with 1008, policy violation). Commands
wait in a queue of :data:`COMMAND_QUEUE_SIZE` (a flooding client loses its oldest commands, not
the server its memory); commands longer than :data:`MAX_COMMAND_CHARS`, not JSON, or with
values that are not numbers (or a speed <= 0) are ignored; seeks and speeds out of range, even
infinite, are clamped.

Run it with ``skyradar serve RUN.zarr`` (binds 127.0.0.1 by default).
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import math
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fastapi import FastAPI, HTTPException, WebSocket, WebSocketDisconnect
from fastapi.responses import FileResponse, JSONResponse

from skyradar.errors import InputError
from skyradar.web.net import origin_allowed
from skyradar.web.source import RunSource

__all__ = [
    "COMMAND_QUEUE_SIZE",
    "MAX_COMMAND_CHARS",
    "SPEED_RANGE",
    "STATIC_DIR",
    "check_speed",
    "create_app",
    "safe_path",
    "serve_in_thread",
]

STATIC_DIR = Path(__file__).parent / "static"
COMMAND_QUEUE_SIZE = 32  # commands waiting per client; a click rate, not a flood, fits
MAX_COMMAND_CHARS = 1024  # the longest real command is about 40 characters
SPEED_RANGE = (0.1, 100.0)  # replay speed limits (times real time)
_POLICY_VIOLATION = 1008  # WebSocket close code
_log = logging.getLogger(__name__)


def check_speed(speed: float, option: str = "--speed") -> float:
    """``speed`` as a float if it is a finite replay speed within :data:`SPEED_RANGE`; else InputError.

    Examples
    --------
    >>> check_speed(4)
    4.0
    >>> check_speed(0)
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: serve: option '--speed' must be from 0.1 to 100 (times real time), got 0
    """
    lo, hi = SPEED_RANGE
    value = float(speed)
    if not lo <= value <= hi:  # also false for NaN
        raise InputError(
            f"serve: option '{option}' must be from {lo:g} to {hi:g} (times real time), got {speed}"
        )
    return value


def _served_files(*tables: Path | None) -> dict[str, Path]:
    """Name -> resolved path of the tables ``/files`` may serve (checked again at each request)."""
    served = {}
    for table in tables:
        if table is not None:
            served[Path(table).name] = Path(table).resolve()
    return served


def safe_path(root: Path, relative: str) -> Path:
    """``root / relative`` if it is a file inside ``root`` after resolving links; else HTTP 403 / 404.

    Examples
    --------
    >>> safe_path(STATIC_DIR, "index.html").name
    'index.html'
    """
    root = root.resolve()
    if "\x00" in relative or relative.startswith(("/", "\\")) or ".." in Path(relative).parts:
        raise HTTPException(status_code=403, detail="path outside the served folder")
    target = (root / relative).resolve()
    if not target.is_relative_to(root):
        raise HTTPException(status_code=403, detail="path outside the served folder")
    if not target.is_file():
        raise HTTPException(status_code=404, detail="not found")
    return target


@dataclass
class _Player:
    index: int = 0
    playing: bool = True
    speed: float = 1.0
    send: bool = True
    ended: bool = False


def create_app(
    run_path: str | Path,
    tracks_path: str | Path | None = None,
    alerts_path: str | Path | None = None,
    speed: float = 1.0,
    autoplay: bool = True,
) -> FastAPI:
    """Build the display app for one run.

    Parameters
    ----------
    run_path : path
        Frames store (``RUN.zarr``; ``RUN.zarr.partial`` while it is being written).
    tracks_path, alerts_path : path, optional
        Tables to display (alerts preferred; tracks are alerted on load; else the run's truth).
    speed : float
        Initial replay speed (1 = real time), within :data:`SPEED_RANGE`.
    autoplay : bool
        Start playing when a client connects.

    Examples
    --------
    >>> import tempfile
    >>> from fastapi.testclient import TestClient
    >>> from skyradar.web.sample import write_sample_run
    >>> run = write_sample_run(Path(tempfile.mkdtemp()) / "run.zarr", n_frames=3)
    >>> with TestClient(create_app(run)) as client:
    ...     client.get("/api/info").json()["n_ready"], client.get("/files/run.zarr").status_code
    (3, 404)
    """
    speed = check_speed(speed)
    tracks_path = Path(tracks_path) if tracks_path else None
    alerts_path = Path(alerts_path) if alerts_path else None
    source = RunSource(run_path, tracks_path, alerts_path)
    served = _served_files(tracks_path, alerts_path)
    app = FastAPI(title="skyradar live display")
    app.state.source = source
    _add_page_routes(app, served)
    _add_run_routes(app, source, autoplay, speed)
    return app


def _add_page_routes(app: FastAPI, served: dict[str, Path]) -> None:
    """The page, its static files, and the tables given on the command line (by exact name)."""

    @app.get("/")
    def index() -> FileResponse:
        return FileResponse(STATIC_DIR / "index.html")

    @app.get("/static/{path:path}")
    def static(path: str) -> FileResponse:
        return FileResponse(safe_path(STATIC_DIR, path))

    @app.get("/files/{name:path}")
    def files(name: str) -> FileResponse:
        # Looked up by exact name: no path is built from the request.
        target = served.get(name)
        if target is None or not target.is_file() or Path(target).resolve() != target:
            raise HTTPException(status_code=404, detail="not found")
        return FileResponse(target, filename=name)


def _add_run_routes(app: FastAPI, source: RunSource, autoplay: bool, speed: float) -> None:
    """The run's summary and frames, and the replay websocket (each client gets its own player)."""

    @app.get("/api/info")
    def info() -> JSONResponse:
        source.refresh()
        return JSONResponse(source.info())

    @app.get("/api/frame/{index}")
    def frame(index: int, image: bool = True) -> JSONResponse:
        source.refresh()
        try:
            return JSONResponse(source.frame(index, with_image=image))
        except IndexError as exc:
            raise HTTPException(status_code=404, detail=str(exc)) from exc

    @app.websocket("/ws")
    async def ws(websocket: WebSocket) -> None:
        await _replay(websocket, source, _Player(playing=autoplay, speed=speed))


async def _replay(websocket: WebSocket, source: RunSource, player: _Player) -> None:
    """One client's replay: same-origin check, then commands in (bounded queue) and frames out."""
    origin, host = websocket.headers.get("origin"), websocket.headers.get("host")
    if not origin_allowed(origin, host, "https" if websocket.url.scheme == "wss" else "http"):
        _log.warning("refused display WebSocket from origin %r (served as %r)", origin, host)
        await websocket.close(code=_POLICY_VIOLATION)
        return
    await websocket.accept()
    queue: asyncio.Queue = asyncio.Queue(maxsize=COMMAND_QUEUE_SIZE)
    reader = asyncio.create_task(_read_commands(websocket, queue))
    try:
        await _play(websocket, source, queue, player)
    except (WebSocketDisconnect, RuntimeError, OSError) as exc:
        # A client that goes away mid-stream ends only its own replay.
        _log.info("display client left: %s", type(exc).__name__)
    finally:
        reader.cancel()
        with contextlib.suppress(asyncio.CancelledError, Exception):
            await reader


def _offer(queue: asyncio.Queue, item: dict[str, Any] | None) -> None:
    """Put ``item`` without waiting; when the queue is full, drop its oldest command first."""
    while True:
        try:
            queue.put_nowait(item)
            return
        except asyncio.QueueFull:
            queue.get_nowait()


def _parse_command(text: Any) -> dict[str, Any] | None:
    """The command in one client message, or None for anything that is not a short JSON object."""
    if not isinstance(text, str) or len(text) > MAX_COMMAND_CHARS:
        return None
    try:
        msg = json.loads(text)
    except (ValueError, RecursionError):  # bad JSON, an int of > 4300 digits, nesting too deep
        return None
    return msg if isinstance(msg, dict) and isinstance(msg.get("cmd"), str) else None


async def _read_commands(websocket: WebSocket, queue: asyncio.Queue) -> None:
    """Forward client commands to ``queue`` (bounded: see :func:`_offer`); ``None`` when the client leaves."""
    try:
        while True:
            msg = _parse_command(await websocket.receive_text())
            if msg is not None:
                _offer(queue, msg)
    except Exception:  # noqa: BLE001 - any receive failure means the client is gone
        _offer(queue, None)


def _number(value: Any) -> float | None:
    """``value`` as a float (may be +-inf) if it is a JSON number that is not NaN; else None."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    value = float(value)  # an int too large for a float cannot come out of a 1 kB message
    return None if math.isnan(value) else value


def _seek_index(cmd: dict[str, Any], source: RunSource, current: int) -> int:
    """Frame index a seek asks for, clamped to the ready frames; ``current`` if the seek is not usable."""
    last = max(source.n_ready - 1, 0)
    if "time_s" in cmd:
        t = _number(cmd["time_s"])
        if t is None:
            return current
        times = source.times[: last + 1]
        index = int(abs(times - min(max(t, times[0]), times[-1])).argmin())  # +-inf: first / last
    else:
        x = _number(cmd.get("index", 0))
        if x is None:
            return current
        index = int(min(max(x, 0.0), float(last)))
    return min(max(index, 0), last)


def _apply(cmd: dict[str, Any], p: _Player, source: RunSource) -> None:
    kind = cmd.get("cmd")
    if kind == "play":
        p.playing, p.ended = True, False
        if p.index >= source.n_ready - 1 and not source.growing:
            p.index, p.send = 0, True  # play again from the start
    elif kind == "pause":
        p.playing = False
    elif kind == "speed":
        value = _number(cmd.get("value", 1.0))
        if value is not None and value > 0:  # a speed of zero or less means nothing: ignored
            p.speed = min(max(value, SPEED_RANGE[0]), SPEED_RANGE[1])
    elif kind == "seek":
        source.refresh()
        p.index = _seek_index(cmd, source, p.index)
        p.send, p.ended = True, False


async def _play(websocket: WebSocket, source: RunSource, queue: asyncio.Queue, p: _Player) -> None:
    loop = asyncio.get_running_loop()
    await asyncio.to_thread(source.refresh)
    await websocket.send_json({**source.info(), "playing": p.playing, "speed": p.speed})
    due = loop.time()
    while True:
        if p.send and p.index < source.n_ready:
            payload = await asyncio.to_thread(source.frame, p.index)
            await websocket.send_json({**payload, "playing": p.playing, "speed": p.speed})
            p.send = False
            nxt = p.index + 1
            step = source.times[nxt] - source.times[p.index] if nxt < len(source.times) else 0.5
            due = loop.time() + max(step, 0.0) / p.speed
        timeout = max(due - loop.time(), 0.0) if p.playing and not p.ended else None
        try:
            msg = await asyncio.wait_for(queue.get(), timeout=timeout)
        except TimeoutError:
            msg = {"cmd": "_tick"}
        if msg is None:
            return
        if msg.get("cmd") != "_tick":
            _apply(msg, p, source)
            continue
        if p.index + 1 >= source.n_ready:
            await asyncio.to_thread(source.refresh)
        if p.index + 1 < source.n_ready:
            p.index, p.send = p.index + 1, True
        elif source.growing:
            due = loop.time() + 0.5  # wait for the writer
        else:
            p.ended = True
            await websocket.send_json({"type": "end", "index": p.index})


@contextlib.contextmanager
def serve_in_thread(app: FastAPI, host: str = "127.0.0.1", timeout_s: float = 20.0) -> Iterator[str]:
    """Run ``app`` with uvicorn on a free port in a background thread; yield its base URL; stop it after.

    Examples
    --------
    >>> from fastapi import FastAPI
    >>> with serve_in_thread(FastAPI()) as url:
    ...     url.startswith("http://127.0.0.1:")
    True
    """
    import uvicorn

    server = uvicorn.Server(uvicorn.Config(app, host=host, port=0, log_level="warning"))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + timeout_s
    while not server.started:
        if time.monotonic() > deadline or not thread.is_alive():
            server.should_exit = True
            raise RuntimeError("display server did not start")
        time.sleep(0.05)
    port = server.servers[0].sockets[0].getsockname()[1]
    try:
        yield f"http://{host}:{port}"
    finally:
        server.should_exit = True
        thread.join(timeout=timeout_s)

"""Live traffic display: FastAPI app that replays a run over a WebSocket to a static page.

Endpoints
---------
``GET /``                 the page (``static/index.html``; no build step)
``GET /static/{path}``    the page's JS and CSS
``GET /files/{path}``     files of the run's folder (tables, report figures); nothing outside it
``GET /api/info``         run summary (frame times, whether it is still being written)
``GET /api/frame/{i}``    one frame's payload as JSON (``?image=false`` leaves out the image)
``WS  /ws``               replay: the server sends ``info`` then ``frame`` messages at the run's
                          pace times the speed; the client sends ``{"cmd": "play"|"pause"}``,
                          ``{"cmd": "speed", "value": 4}``, ``{"cmd": "seek", "index": 12}`` or
                          ``{"cmd": "seek", "time_s": 30.5}``. At the end of a finished run the
                          server sends ``{"type": "end"}`` and pauses; a growing run is polled.

Run it with ``skyradar serve RUN.zarr`` (binds 127.0.0.1 by default).
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fastapi import FastAPI, HTTPException, WebSocket, WebSocketDisconnect
from fastapi.responses import FileResponse, JSONResponse

from skyradar.web.source import RunSource

__all__ = ["STATIC_DIR", "create_app", "safe_path", "serve_in_thread"]

STATIC_DIR = Path(__file__).parent / "static"
_log = logging.getLogger(__name__)


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
    files_root: str | Path | None = None,
) -> FastAPI:
    """Build the display app for one run.

    Parameters
    ----------
    run_path : path
        Frames store (``RUN.zarr``; ``RUN.zarr.partial`` while it is being written).
    tracks_path, alerts_path : path, optional
        Tables to display (alerts preferred; tracks are alerted on load; else the run's truth).
    speed : float
        Initial replay speed (1 = real time).
    autoplay : bool
        Start playing when a client connects.
    files_root : path, optional
        Folder served under ``/files`` (default: the folder holding the run).
    """
    source = RunSource(
        run_path, Path(tracks_path) if tracks_path else None, Path(alerts_path) if alerts_path else None
    )
    root = Path(files_root) if files_root else Path(run_path).resolve().parent
    app = FastAPI(title="skyradar live display")
    app.state.source = source

    @app.get("/")
    def index() -> FileResponse:
        return FileResponse(STATIC_DIR / "index.html")

    @app.get("/static/{path:path}")
    def static(path: str) -> FileResponse:
        return FileResponse(safe_path(STATIC_DIR, path))

    @app.get("/files/{path:path}")
    def files(path: str) -> FileResponse:
        return FileResponse(safe_path(root, path))

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
        await websocket.accept()
        queue: asyncio.Queue = asyncio.Queue()
        reader = asyncio.create_task(_read_commands(websocket, queue))
        try:
            await _play(websocket, source, queue, _Player(playing=autoplay, speed=speed))
        except (WebSocketDisconnect, RuntimeError, OSError) as exc:
            # A client that goes away mid-stream ends only its own replay.
            _log.info("display client left: %s", type(exc).__name__)
        finally:
            reader.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await reader

    return app


async def _read_commands(websocket: WebSocket, queue: asyncio.Queue) -> None:
    """Forward client commands to ``queue``; ``None`` when the client disconnects."""
    try:
        while True:
            text = await websocket.receive_text()
            try:
                msg = json.loads(text)
            except json.JSONDecodeError:
                continue
            if isinstance(msg, dict):
                await queue.put(msg)
    except Exception:  # noqa: BLE001 - any receive failure means the client is gone
        await queue.put(None)


def _apply(cmd: dict[str, Any], p: _Player, source: RunSource) -> None:
    kind = cmd.get("cmd")
    if kind == "play":
        p.playing, p.ended = True, False
        if p.index >= source.n_ready - 1 and not source.growing:
            p.index, p.send = 0, True  # play again from the start
    elif kind == "pause":
        p.playing = False
    elif kind == "speed":
        with contextlib.suppress(TypeError, ValueError):
            p.speed = min(max(float(cmd.get("value", 1.0)), 0.1), 100.0)
    elif kind == "seek":
        source.refresh()
        if "time_s" in cmd:
            with contextlib.suppress(TypeError, ValueError):
                t = float(cmd["time_s"])
                p.index = int(abs(source.times[: max(source.n_ready, 1)] - t).argmin())
        else:
            with contextlib.suppress(TypeError, ValueError):
                p.index = int(cmd.get("index", 0))
        p.index = min(max(p.index, 0), max(source.n_ready - 1, 0))
        p.send, p.ended = True, False


async def _play(websocket: WebSocket, source: RunSource, queue: asyncio.Queue, p: _Player) -> None:
    loop = asyncio.get_running_loop()
    await asyncio.to_thread(source.refresh)
    await websocket.send_json({**source.info(), "playing": p.playing, "speed": p.speed})
    due = loop.time()
    while True:
        if p.send and p.index < source.n_ready:
            await websocket.send_json(await asyncio.to_thread(source.frame, p.index))
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

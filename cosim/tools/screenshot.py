"""Screenshot of a recording as a user first sees it: Rerun's own web viewer in a headless Chromium.

    python -m cosim.tools.screenshot RUN/pour.rrd --out docs/recording.png [--size 1600x1000]

Serves the recording with ``rerun --web-viewer`` (on free local ports), opens the viewer in Chromium without a
display (software WebGL: SwiftShader), and drives it over the Chrome DevTools protocol: it captures the page every
``--poll`` s until the page has not changed for ``--settle`` s (the viewer has loaded the recording and drawn it;
a shorter pause can be the viewer waiting for data) or ``--timeout`` s have passed, then writes the last capture
and prints when the page last changed: the load time of the recording in a software-rendered browser. The viewer opens a recording at its last logged time: for a picture of
the middle of a pour, record a run that stops there (``cosim pour --duration``). Needs ``chromium`` on the PATH
and the ``websockets`` package (``pip install cosim[screenshot]``). Nothing is written unless a capture was made.
"""

from __future__ import annotations

import argparse
import asyncio
import base64
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.parse
import urllib.request
from pathlib import Path

from cosim.atomic_files import atomic_path

# Chromium without a display or GPU: WebGL through SwiftShader, and none of its background traffic.
CHROMIUM_FLAGS = (
    "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
    "--disable-background-networking", "--disable-component-update", "--disable-sync", "--no-first-run",
    "--disable-dev-shm-usage", "--hide-scrollbars",
)
# s: how long a server or the browser may take to answer its first request.
START_TIMEOUT = 30.0


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _wait_http(url: str, timeout: float) -> bytes:
    """The body of ``url`` once it answers (polled every 0.2 s); TimeoutError after ``timeout`` s."""
    end = time.monotonic() + timeout
    while True:
        try:
            with urllib.request.urlopen(url, timeout=2.0) as response:
                return response.read()
        except OSError:
            if time.monotonic() > end:
                raise TimeoutError(f"{url} did not answer within {timeout:.0f} s") from None
            time.sleep(0.2)


def viewer_url(web_port: int, grpc_port: int) -> str:
    """URL of the web viewer showing the recording served on ``grpc_port``."""
    source = urllib.parse.quote(f"rerun+http://127.0.0.1:{grpc_port}/proxy", safe="")
    return f"http://127.0.0.1:{web_port}/?url={source}"


async def _capture(devtools_port: int, url: str, width: int, height: int, poll: float, settle: float,
                   timeout: float) -> tuple[bytes, float]:
    """(PNG, seconds from navigation to the page's last change) of ``url`` in the browser on ``devtools_port``, once
    the page has not changed for ``settle`` s (or ``timeout`` s after navigating)."""
    import websockets

    pages = json.loads(_wait_http(f"http://127.0.0.1:{devtools_port}/json/list", START_TIMEOUT))
    target = next(p for p in pages if p.get("type") == "page")
    async with websockets.connect(target["webSocketDebuggerUrl"], max_size=None) as ws:
        ids = iter(range(1, 1 << 30))

        async def call(method: str, **params) -> dict:
            k = next(ids)
            await ws.send(json.dumps({"id": k, "method": method, "params": params}))
            while True:
                message = json.loads(await ws.recv())
                if message.get("id") == k:
                    if "error" in message:
                        raise RuntimeError(f"{method}: {message['error']}")
                    return message.get("result", {})

        await call("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1, mobile=False)
        start = time.monotonic()
        await call("Page.navigate", url=url)
        last, changed = None, 0.0
        while True:
            await asyncio.sleep(poll)
            png = base64.b64decode((await call("Page.captureScreenshot", format="png"))["data"])
            now = time.monotonic() - start
            if png != last:
                last, changed = png, now
            if now - changed >= settle or now > timeout:
                return png, changed


def _stop_group(process: subprocess.Popen) -> None:
    """End ``process`` and every process it started (its process group): SIGTERM, then SIGKILL after 10 s."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(process.pid, sig)
        except ProcessLookupError:
            return
        try:
            process.wait(timeout=10)
            os.killpg(process.pid, 0)  # the leader has exited: is any child of its group left?
        except subprocess.TimeoutExpired:
            continue
        except ProcessLookupError:
            return


def screenshot(recording: Path, out: Path, size: tuple[int, int], poll: float, settle: float, timeout: float) -> float:
    """Write the screenshot of ``recording`` to ``out``; returns the seconds the viewer took to load and draw it (when
    the page last changed)."""
    rerun = shutil.which("rerun", path=os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")]))
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if rerun is None or chromium is None:
        raise SystemExit(f"cosim.tools.screenshot: error: needs 'rerun' and 'chromium' on the PATH (found {rerun}, {chromium})")
    web_port, grpc_port, devtools_port = _free_port(), _free_port(), _free_port()
    started: list[subprocess.Popen] = []
    with tempfile.TemporaryDirectory(prefix="cosim-screenshot-") as profile:
        try:
            started.append(subprocess.Popen(
                [rerun, "--web-viewer", "--web-viewer-port", str(web_port), "--port", str(grpc_port), str(recording)],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env={**os.environ, "BROWSER": "true"},
                start_new_session=True,  # its own process group: the `rerun` script starts the viewer's binary as a child
            ))
            _wait_http(f"http://127.0.0.1:{web_port}/", START_TIMEOUT)
            started.append(subprocess.Popen(
                [chromium, *CHROMIUM_FLAGS, f"--remote-debugging-port={devtools_port}", f"--user-data-dir={profile}",
                 f"--window-size={size[0]},{size[1]}", "about:blank"],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
            ))
            url = viewer_url(web_port, grpc_port)
            png, elapsed = asyncio.run(_capture(devtools_port, url, size[0], size[1], poll, settle, timeout))
        finally:
            for process in reversed(started):
                _stop_group(process)
    with atomic_path(out) as tmp:
        Path(tmp).write_bytes(png)
    return elapsed


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, got {text!r}") from None
    if not (320 <= w <= 4096 and 240 <= h <= 4096):
        raise argparse.ArgumentTypeError(f"must be in [320, 4096] x [240, 4096] pixels, got {text!r}")
    return w, h


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.tools.screenshot", description=__doc__.split("\n\n")[0])
    parser.add_argument("recording", type=Path, help="a pour.rrd (or a run folder holding one)")
    parser.add_argument("--out", type=Path, required=True, help="PNG to write")
    parser.add_argument("--size", type=_size, default=(1600, 1000), help="window WIDTHxHEIGHT in pixels (default 1600x1000)")
    parser.add_argument("--poll", type=float, default=3.0, help="s between captures while the viewer loads, in (0, 60]")
    parser.add_argument("--settle", type=float, default=20.0, help="s the page must stay unchanged, in (0, 600]")
    parser.add_argument("--timeout", type=float, default=300.0, help="s to wait for the viewer to settle, in (0, 3600]")
    args = parser.parse_args(argv)
    recording = args.recording / "pour.rrd" if args.recording.is_dir() else args.recording
    if not recording.is_file():
        parser.error(f"recording: no file at {recording}")
    if not 0.0 < args.poll <= 60.0:
        parser.error(f"--poll: must be in (0, 60] s, got {args.poll}")
    if not 0.0 < args.settle <= 600.0:
        parser.error(f"--settle: must be in (0, 600] s, got {args.settle}")
    if not 0.0 < args.timeout <= 3600.0:
        parser.error(f"--timeout: must be in (0, 3600] s, got {args.timeout}")
    if not args.out.parent.is_dir():
        parser.error(f"--out: folder {args.out.parent} does not exist")
    elapsed = screenshot(recording.resolve(), args.out, args.size, args.poll, args.settle, args.timeout)
    print(f"{args.out}: the page last changed {elapsed:.1f} s after it was opened")
    return 0


if __name__ == "__main__":
    sys.exit(main())

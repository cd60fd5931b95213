"""A station for the browser client's journeys and benchmark: an emulated switch on a
real pseudo-terminal in this process, and ``moas-server --headless`` as a separate
process serving the page, with its own XDG directories."""

from __future__ import annotations

import asyncio
import json
import os
import shutil
import socket
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from moas_gui.config import Config, load_config
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, make_link, serve

ROOT = Path(__file__).resolve().parent.parent
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
CHROMEDRIVER = shutil.which("chromedriver") or "/usr/bin/chromedriver"


def browser_missing() -> str | None:
    """Why no browser test can run here, or None when one can."""
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "selenium is not installed (pip install -e '.[test]')"
    for path in (CHROMIUM, CHROMEDRIVER):
        if not os.access(path, os.X_OK):
            return (f"{path} is missing: Debian's chromium and chromium-driver are not "
                    "installed (scripts/setup.sh --test installs them as root)")
    return None


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


async def until(condition: Callable[[], Any], timeout: float = 10.0, what: str = "") -> Any:
    loop = asyncio.get_running_loop()
    end = loop.time() + timeout
    while True:
        value = condition()
        if value:
            return value
        if loop.time() > end:
            raise AssertionError(f"not in {timeout} s: {what or 'condition'}")
        await asyncio.sleep(0.02)


def _out_of_reach(endpoint: PtyEndpoint) -> None:
    """Moves the pseudo-terminal's descriptors to high numbers.  Run after the Qt window
    tests in one process, something of theirs now and then closes a descriptor number
    it no longer owns; when that number is this pseudo-terminal's, the server sees the
    switch's cable pulled.  High numbers are not reused that way."""
    import fcntl

    for name in ("_master", "_slave"):
        fd = getattr(endpoint, name)
        high = fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 800)
        os.close(fd)
        setattr(endpoint, name, high)


class Station:
    """The emulated switch, the configuration and the server process."""

    def __init__(self, tmp: Path, example: str = "small-station.moas") -> None:
        self.tmp = tmp
        self.link = tmp / "moas1"
        self.box = EmulatedBox()
        self.endpoint = PtyEndpoint()
        _out_of_reach(self.endpoint)
        serve(self.box, self.endpoint, asyncio.get_running_loop())
        make_link(self.endpoint.path, self.link)
        data = json.loads((ROOT / "examples" / example).read_text())
        data["Switches"][0]["Port"] = str(self.link)
        data["UseN1MMLogger"] = False
        self.config_path = tmp / "station.moas"
        self.config_path.write_text(json.dumps(data, indent=2))
        self.config: Config = load_config(self.config_path).unwrap()
        self.tcp, self.web = free_port(), free_port()
        self.process: asyncio.subprocess.Process | None = None
        self.log: list[str] = []
        self._collector: asyncio.Task[None] | None = None
        self.env = dict(os.environ, PYTHONUNBUFFERED="1")
        for name in ("XDG_RUNTIME_DIR", "XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_CACHE_HOME",
                     "XDG_STATE_HOME"):
            folder = tmp / name.lower()
            folder.mkdir(mode=0o700, exist_ok=True)
            self.env[name] = str(folder)

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.web}/"

    async def start_server(self, *extra: str) -> None:
        self.process = await asyncio.create_subprocess_exec(
            sys.executable, "-m", "moas_gui.cli.server", "--headless", str(self.config_path),
            "--bind", "127.0.0.1", "--tcp-port", str(self.tcp), "--udp-port", str(free_port()),
            "--web-port", str(self.web), "--no-rotator-program", "--new-instance", *extra,
            stderr=asyncio.subprocess.PIPE, env=self.env)
        self._collector = asyncio.create_task(self._collect(self.process))
        await until(lambda: any("Opened" in line for line in self.log), 30,
                    "the server opens its configuration")

    async def _collect(self, process: asyncio.subprocess.Process) -> None:
        assert process.stderr is not None
        async for line in process.stderr:
            self.log.append(line.decode(errors="replace"))

    async def stop_server(self) -> None:
        process, self.process = self.process, None
        if process is None:
            return
        if process.returncode is None:
            process.terminate()
            try:
                await asyncio.wait_for(process.wait(), 15)
            except TimeoutError:
                process.kill()
                await process.wait()
        if self._collector is not None:
            await self._collector

    def pages(self) -> int:
        """Browser clients connected now, as the server's log tells."""
        connected = sum("Browser client connected from" in line for line in self.log)
        gone = sum("Browser client " in line and "connected from" not in line
                   for line in self.log)
        return connected - gone

    def relays(self) -> frozenset[int]:
        return frozenset(self.box.view().relays)

    def relays_of(self, antenna: int, khz: float, station: int = 1, radio: int = 1) -> frozenset[int]:
        found = self.config.antenna(antenna)
        assert found is not None
        return frozenset(next(e.relays for c in found.control if c.range.contains(khz)
                              for e in c.stations if e.applies_to(station, radio)))

    async def close(self) -> None:
        await self.stop_server()
        self.endpoint.close()
        self.box.close()


class Protocol:
    """A TCP client of the server, for what the page does not do (frequencies)."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader, self.writer = reader, writer
        self.next_id = 1

    @classmethod
    async def connect(cls, port: int) -> Protocol:
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        client = cls(reader, writer)
        await client.call("hello", client="journey")
        return client

    async def call(self, cmd: str, **args: Any) -> dict[str, Any]:
        ident = self.next_id
        self.next_id += 1
        self.writer.write(json.dumps({"id": ident, "cmd": cmd, **args}).encode() + b"\n")
        while True:
            message = json.loads(await asyncio.wait_for(self.reader.readline(), 10))
            if message.get("id") == ident:
                assert message["ok"], message
                return message["result"]  # type: ignore[no-any-return]

    async def close(self) -> None:
        self.writer.close()
        await self.writer.wait_closed()


def chrome(profile: Path, width: int = 1024, height: int = 600) -> Any:
    """Debian's Chromium, headless, driven by Debian's chromedriver (no download)."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--no-first-run", "--disable-extensions", f"--user-data-dir={profile}"):
        options.add_argument(argument)
    driver = webdriver.Chrome(options=options, service=Service(CHROMEDRIVER))
    viewport(driver, width, height)
    return driver


def blank(driver: Any, width: int = 1024, height: int = 600) -> None:
    """The browser as :func:`chrome` starts it: one window on a blank page at the size
    given, and nothing a page stored (localStorage, cookies, cache) for any server it saw
    (the suite shares one Chromium among the tests of a worker: tests/conftest.py)."""
    handles = driver.window_handles
    origins: set[str] = set()
    for handle in handles:
        driver.switch_to.window(handle)
        history = driver.execute_cdp_cmd("Page.getNavigationHistory", {})
        for entry in history["entries"]:
            url = entry["url"]
            if url.startswith(("http://", "https://")):
                origins.add("/".join(url.split("/", 3)[:3]))
        if handle != handles[0]:
            driver.close()
    driver.switch_to.window(handles[0])
    if driver.current_url != "about:blank":  # a navigation costs Chromium about 50 ms
        driver.get("about:blank")
    for origin in origins:
        driver.execute_cdp_cmd("Storage.clearDataForOrigin",
                               {"origin": origin, "storageTypes": "all"})
    driver.execute_cdp_cmd("Network.clearBrowserCookies", {})
    driver.execute_cdp_cmd("Network.clearBrowserCache", {})
    driver.execute_cdp_cmd("Page.resetNavigationHistory", {})
    viewport(driver, width, height)


_WAIT_IN_PAGE = """
const [body, limit, done] = [arguments[0], arguments[1], arguments[arguments.length - 1]];
const check = new Function(body);
const end = performance.now() + limit;
(function look() {
  let value;
  try { value = check(); } catch (error) { done({error: String(error)}); return; }
  if (value) { done({value: value}); return; }
  if (performance.now() > end) { done(null); return; }
  setTimeout(look, 20);
})();
"""


async def wait_in_page(driver: Any, script: str, timeout: float, what: str) -> Any:
    """Waits until ``script`` (a function body, as for ``execute_script``) returns a true
    value in the page, and returns that value.  The page itself looks every 20 ms and
    answers once: one call to the browser a wait, where asking from here every few
    milliseconds cost the browser and its driver about 6 ms of processor time a look.
    A script that throws fails the wait at once, as ``execute_script`` would."""
    def wait() -> Any:
        driver.set_script_timeout(timeout + 30)
        return driver.execute_async_script(_WAIT_IN_PAGE, script, timeout * 1000)

    got = await asyncio.to_thread(wait)
    if got is None:
        raise AssertionError(f"the page did not show {what or script} in {timeout:g} s")
    if "error" in got:
        raise AssertionError(f"the page's script failed ({got['error']}): {script}")
    return got["value"]


def viewport(driver: Any, width: int, height: int, mobile: bool = True) -> None:
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride", {
        "width": width, "height": height, "deviceScaleFactor": 1, "mobile": mobile})


class FakeWeb:
    """The page served by the real protocol and web servers over the fake backend (the
    demo station) on 127.0.0.1: for journeys that need to set any state at will."""

    def __init__(self) -> None:
        from moas_gui.net.server import ClientServer
        from moas_gui.testing.fake_backend import FakeBackend

        self.backend = FakeBackend()
        self.clients = ClientServer(self.backend, host="127.0.0.1", port=0)
        self.backend.attach(self.clients)
        self.web: Any = None
        self.port = 0

    @classmethod
    async def start(cls) -> FakeWeb:
        made = cls()
        await made.clients.start()
        await made.serve()
        return made

    async def serve(self) -> None:
        """Serves the page (again, on the same port after :meth:`stop_serving`)."""
        from moas_gui.net.web import WebServer

        self.web = WebServer(self.clients, host="127.0.0.1", port=self.port)
        await self.web.start()
        self.port = self.web.port

    async def stop_serving(self) -> None:
        """The page's server goes away (the pages lose their connection)."""
        await self.web.close()

    def url(self, query: str = "station=1&radio=1") -> str:
        return f"http://127.0.0.1:{self.port}/?{query}"

    def sent(self, cmd: str) -> int:
        """How many ``cmd`` requests the backend was given."""
        return len([c for c in self.backend.calls if c[0] == cmd])

    async def close(self, driver: Any) -> None:
        """The page leaves first (so the server sees it go), then the servers close."""
        await asyncio.to_thread(driver.get, "about:blank")
        await until(lambda: not self.clients.clients(), 5, "the page gone")
        await self.web.close()
        await self.clients.close()

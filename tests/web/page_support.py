"""The page tests' harness (tests/integration/test_page*.py): the ROS side a module's tests look
at, Debian's chromium driven by Playwright, one tab of the page, and the screenshot folder.

A module makes its fixtures from the factories here::

    class PageSystem(System):
        def up(self):
            self.start_core()
            ...                      # the nodes the module's tests look at
            self.start_web()

    system = system_fixture(PageSystem, "page")
    browser = browser_fixture("--enable-precise-memory-info")
    shots = shots_fixture()

Screenshots go to ``$MINROS_SCREENSHOTS`` when set (the README's pictures are made with
``MINROS_SCREENSHOTS=docs/screenshots``), else to a temporary folder.
"""

from __future__ import annotations

import os
import xmlrpc.client
from pathlib import Path
from typing import Callable, Dict, List, Optional, Sequence

import pytest

from support import (
    CHROMIUM,
    PYTHON,
    Proc,
    free_port,
    launch_chromium,
    need,
    reference_env,
    ros_env,
    wait_for_master,
)

try:
    from playwright import sync_api as playwright_api
except ImportError:
    playwright_api = None


def require_browser() -> None:
    """Skip locally, fail in CI, without Playwright or Debian's chromium."""
    need(playwright_api is not None, "playwright is needed for the page tests (the test extra)")
    need(Path(CHROMIUM).exists(), "Debian's chromium is needed for the page tests")


class System:
    """The ROS side of a page test module: a master, what runs beside it and ``minros web``,
    each with one environment (``env``), started in order by :meth:`up` and stopped in
    reverse; a start that fails stops what did come up."""

    def __init__(self, tmp: Path, extra_env: Optional[Dict[str, str]] = None) -> None:
        self.tmp = tmp
        self.home = tmp / "ros_home"
        (self.home / "log").mkdir(parents=True)
        self.port = free_port()
        self.env = ros_env(self.port, self.home, extra_env)
        self.procs: List[Proc] = []
        self.web_port = 0
        self.web: Optional[Proc] = None
        self.master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{self.port}/")
        try:
            self.up()
        except BaseException:
            self.stop()  # no fixture stops what never came up
            raise

    def up(self) -> None:
        """Start the module's processes (a subclass's)."""
        self.start_core()
        self.start_web()

    def start(self, argv: Sequence[str], extra: Optional[Dict[str, str]] = None,
              reference: bool = False) -> Proc:
        """A process in this system's environment (plus ``extra``; Debian's with
        ``reference``), stopped with the system."""
        env = dict(self.env, **extra) if extra else self.env
        proc = Proc(argv, reference_env(env) if reference else env)
        self.procs.append(proc)
        return proc

    def start_core(self, wrap: Callable[[List[str]], List[str]] = list) -> Proc:
        """``minros core`` on this system's port (``wrap`` may put it under ``minros trace``)."""
        core = self.start(wrap([PYTHON, "-m", "minros", "core", "-p", str(self.port)]))
        wait_for_master(self.port)
        return core

    def start_web(self, *args: str) -> Proc:
        """``minros web`` on a free port, with ``args``; returns once it listens."""
        self.web_port = free_port()
        self.web = self.start([PYTHON, "-m", "minros", "web", "--port", str(self.web_port), *args])
        self.web.read_until("listening on", timeout=30)
        return self.web

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.web_port}/"

    def stop(self) -> str:
        """Stop every process, the last started first; their output."""
        return "".join(proc.stop() for proc in reversed(self.procs))

    def check_stopped(self, output: str) -> None:
        """What must hold once the system is stopped (``output`` is what its processes wrote)."""
        assert "Traceback" not in output, output[-4000:]


def system_fixture(make: Callable[[Path], System], name: str):
    """A module-scoped fixture: the system ``make(folder)`` starts, stopped and checked at the
    end of the module."""
    @pytest.fixture(scope="module")
    def fixture(tmp_path_factory):
        require_browser()
        made = make(tmp_path_factory.mktemp(name))
        try:
            yield made
        finally:
            made.check_stopped(made.stop())

    return fixture


def browser_fixture(*chromium_args: str, after: str = "system"):
    """A module-scoped fixture: Debian's chromium with ``chromium_args``, launched once the
    fixture ``after`` (the module's system) is up, and closed before it stops."""
    @pytest.fixture(scope="module")
    def fixture(request):
        request.getfixturevalue(after)
        require_browser()
        with playwright_api.sync_playwright() as p:
            browser = launch_chromium(p, *chromium_args)
            try:
                yield browser
            finally:
                browser.close()

    return fixture


def shots_fixture():
    """A module-scoped fixture: the folder screenshots go to."""
    @pytest.fixture(scope="module")
    def fixture(tmp_path_factory) -> Path:
        folder = Path(os.environ.get("MINROS_SCREENSHOTS") or tmp_path_factory.mktemp("screenshots"))
        folder.mkdir(parents=True, exist_ok=True)
        return folder

    return fixture


class Page:
    """One tab on the page (a browser context of its own), its console errors collected:
    closing it fails the test if the page logged any."""

    #: a screenshot smaller than this is a blank page
    MIN_SHOT_BYTES = 10_000

    def __init__(self, browser, system: System, shots: Path, width: int = 1280,
                 height: int = 800) -> None:
        self.context = browser.new_context(viewport={"width": width, "height": height})
        self.page = self.context.new_page()
        self.errors: list = []
        self.page.on("pageerror", lambda exc: self.errors.append(str(exc)))
        self.page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.system = system
        self.shots = shots

    def open(self, hash_: str) -> None:
        """The page at view ``hash_``, once connected and holding the graph."""
        self.page.goto(self.system.url + "#" + hash_)
        self.page.wait_for_function("window.minrosPage && minrosPage.conn.state === 'connected' "
                                    "&& minrosPage.graph.version > 0", timeout=20_000)

    def view(self, name: str):
        return self.page.locator(f'.view[data-view="{name}"]')

    def js(self, expression: str, arg=None):
        return self.page.evaluate(expression, arg)

    def wait(self, expression: str, timeout: float = 20_000) -> None:
        self.page.wait_for_function(expression, timeout=timeout)

    def shot(self, name: str) -> Path:
        """``name``.png of the tab, every view scrolled to its top."""
        self.page.evaluate("document.querySelectorAll('.view').forEach((v) => { v.scrollTop = 0; })")
        path = self.shots / f"{name}.png"
        self.page.screenshot(path=str(path))
        assert path.stat().st_size > self.MIN_SHOT_BYTES
        return path

    def close(self) -> None:
        self.context.close()
        assert not self.errors, self.errors

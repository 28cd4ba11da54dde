"""The interactive viewers in a real browser: headless Debian chromium, driven over the DevTools protocol.

The pages are opened from ``file://``; the tests move the slider with key events, switch branches, orbit the
view with the mouse, check that the drawing changes (a hash of the canvas pixels), that the console reports no
error, and that no request leaves the page (chromium also runs with every host name mapped to nothing). Each
test saves a screenshot into its pytest tmp dir.

The DevTools protocol is spoken over ``--remote-debugging-pipe`` (NUL-separated JSON on file descriptors 3 and
4), so no browser-driver package is needed. Skipped, with the reason, when ``/usr/bin/chromium`` is absent
(``apt-get install chromium``; CI installs it).
"""

from __future__ import annotations

import base64
import fcntl
import json
import os
import shutil
import subprocess
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import linkwork as lw
from linkwork.data import example
from linkwork.viz.viewer import write_synthesis_viewer, write_trace_viewer

CHROMIUM = "/usr/bin/chromium"
pytestmark = pytest.mark.skipif(
    not Path(CHROMIUM).exists(),
    reason=f"{CHROMIUM} is absent: apt-get install chromium to run the browser tests",
)

FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-extensions",
    "--mute-audio",
    # Any host name resolves to nothing: a request to another host could not succeed even if one were made.
    "--host-resolver-rules=MAP * ~NOTFOUND",
    "--remote-debugging-pipe",
]

#: Seconds to wait for one DevTools answer or event.
TIMEOUT = 20.0


class Browser:
    """Headless chromium with one page, driven over the DevTools protocol on a pipe."""

    def __init__(self, profile: Path, width: int = 1400, height: int = 1100) -> None:
        to_chrome_r, to_chrome_w = os.pipe()
        from_chrome_r, from_chrome_w = os.pipe()
        # Move the child's ends above 10 so that placing them on 3 and 4 cannot clobber one another.
        child_in = fcntl.fcntl(to_chrome_r, fcntl.F_DUPFD_CLOEXEC, 10)
        child_out = fcntl.fcntl(from_chrome_w, fcntl.F_DUPFD_CLOEXEC, 10)
        os.close(to_chrome_r)
        os.close(from_chrome_w)

        def on_3_and_4() -> None:
            os.dup2(child_in, 3)
            os.dup2(child_out, 4)

        self.proc = subprocess.Popen(
            [
                CHROMIUM,
                *FLAGS,
                f"--user-data-dir={profile}",
                f"--window-size={width},{height}",
                "about:blank",
            ],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            close_fds=False,
            preexec_fn=on_3_and_4,
        )
        os.close(child_in)
        os.close(child_out)
        self._write = to_chrome_w
        self._read = from_chrome_r
        self._next = 0
        self._replies: dict[int, dict[str, Any]] = {}
        self.events: list[dict[str, Any]] = []
        self._cond = threading.Condition()
        self._reader = threading.Thread(target=self._pump, daemon=True)
        self._reader.start()
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Page", "Runtime", "Log", "Network"):
            self.call(f"{domain}.enable", session=True)
        self.call(
            "Emulation.setDeviceMetricsOverride",
            {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False},
            session=True,
        )

    def _pump(self) -> None:
        buffer = b""
        while True:
            try:
                chunk = os.read(self._read, 1 << 16)
            except OSError:
                chunk = b""
            if not chunk:
                with self._cond:
                    self._cond.notify_all()
                return
            buffer += chunk
            *messages, buffer = buffer.split(b"\0")
            with self._cond:
                for raw in messages:
                    msg = json.loads(raw)
                    if "id" in msg:
                        self._replies[msg["id"]] = msg
                    else:
                        self.events.append(msg)
                self._cond.notify_all()

    def call(
        self, method: str, params: dict[str, Any] | None = None, session: bool = False
    ) -> dict[str, Any]:
        """Send one command and wait for its answer; a protocol error raises."""
        self._next += 1
        msg: dict[str, Any] = {"id": self._next, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = self.session
        os.write(self._write, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + TIMEOUT
        with self._cond:
            while self._next not in self._replies:
                left = deadline - time.monotonic()
                if left <= 0 or self.proc.poll() is not None:
                    raise TimeoutError(f"no answer to {method} within {TIMEOUT} s")
                self._cond.wait(left)
            reply = self._replies.pop(self._next)
        if "error" in reply:
            raise RuntimeError(f"{method}: {reply['error']}")
        return reply.get("result", {})

    def wait_event(self, method: str, since: int) -> dict[str, Any]:
        """The first event ``method`` received after the ``since``-th event."""
        deadline = time.monotonic() + TIMEOUT
        with self._cond:
            while True:
                for ev in self.events[since:]:
                    if ev.get("method") == method:
                        return ev
                left = deadline - time.monotonic()
                if left <= 0:
                    raise TimeoutError(f"no {method} event within {TIMEOUT} s")
                self._cond.wait(left)

    def open(self, file: Path, fragment: str = "") -> None:
        """Navigate to a local file and wait for its load event."""
        # A change of fragment alone would not reload the page: leave it first.
        for url in ("about:blank", file.resolve().as_uri() + fragment):
            mark = len(self.events)
            self.call("Page.navigate", {"url": url}, session=True)
            self.wait_event("Page.loadEventFired", mark)

    def js(self, expression: str) -> Any:
        """Evaluate an expression in the page and return its value (a thrown exception fails the test)."""
        result = self.call(
            "Runtime.evaluate",
            {"expression": expression, "returnByValue": True, "awaitPromise": True},
            session=True,
        )
        if "exceptionDetails" in result:
            raise AssertionError(f"{expression!r} threw: {result['exceptionDetails']}")
        return result["result"].get("value")

    def key(self, key: str, code: int) -> None:
        """Press and release one key on the focused element."""
        for kind in ("rawKeyDown", "keyUp"):
            self.call(
                "Input.dispatchKeyEvent",
                {"type": kind, "key": key, "code": key, "windowsVirtualKeyCode": code},
                session=True,
            )

    def drag(self, x0: float, y0: float, x1: float, y1: float, steps: int = 8) -> None:
        """Drag with the left mouse button from (x0, y0) to (x1, y1), page coordinates."""
        self.call("Input.dispatchMouseEvent", {"type": "mouseMoved", "x": x0, "y": y0}, session=True)
        common = {"button": "left", "clickCount": 1}
        self.call(
            "Input.dispatchMouseEvent", {"type": "mousePressed", "x": x0, "y": y0, **common}, session=True
        )
        for t in np.linspace(0, 1, steps)[1:]:
            x, y = x0 + t * (x1 - x0), y0 + t * (y1 - y0)
            self.call(
                "Input.dispatchMouseEvent", {"type": "mouseMoved", "x": x, "y": y, "buttons": 1}, session=True
            )
        self.call(
            "Input.dispatchMouseEvent", {"type": "mouseReleased", "x": x1, "y": y1, **common}, session=True
        )

    def screenshot(self, file: Path) -> Path:
        """Save a PNG of the whole page."""
        height = self.js("Math.ceil(document.documentElement.scrollHeight)")
        width = self.js("Math.ceil(document.documentElement.scrollWidth)")
        shot = self.call(
            "Page.captureScreenshot",
            {
                "format": "png",
                "captureBeyondViewport": True,
                "clip": {"x": 0, "y": 0, "width": width, "height": height, "scale": 1},
            },
            session=True,
        )
        file.write_bytes(base64.b64decode(shot["data"]))
        return file

    def errors(self) -> list[str]:
        """Every console error, uncaught exception and error log entry so far."""
        out = []
        for ev in self.events:
            method, params = ev.get("method"), ev.get("params", {})
            if method == "Runtime.exceptionThrown":
                out.append(json.dumps(params["exceptionDetails"])[:500])
            elif method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
                out.append(json.dumps(params.get("args"))[:500])
            elif method == "Log.entryAdded" and params["entry"].get("level") == "error":
                out.append(f"{params['entry'].get('source')}: {params['entry'].get('text')}")
        return out

    def requests(self) -> list[str]:
        """The URL of every request the page made."""
        return [
            ev["params"]["request"]["url"]
            for ev in self.events
            if ev.get("method") == "Network.requestWillBeSent"
        ]

    def close(self) -> None:
        try:
            self.call("Browser.close")
        except (TimeoutError, RuntimeError, OSError):
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        os.close(self._write)
        os.close(self._read)


@pytest.fixture(scope="module")
def browser(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Browser]:
    profile = tmp_path_factory.mktemp("chromium-profile")
    b = Browser(profile)
    yield b
    b.close()
    shutil.rmtree(profile, ignore_errors=True)


CANVAS_HASH = """(() => {
  const c = document.getElementById(%r);
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let h = 2166136261, ink = 0;
  for (let i = 0; i < d.length; i += 4) {
    h = Math.imul(h ^ d[i] ^ (d[i + 1] << 8) ^ (d[i + 2] << 16), 16777619) >>> 0;
    if (d[i] < 250 || d[i + 1] < 250 || d[i + 2] < 250) ink++;
  }
  return [h, ink / (d.length / 4)];
})()"""


def canvas(browser: Browser, element: str = "scene") -> tuple[int, float]:
    """A hash of a canvas's pixels and the fraction of its pixels that are not white."""
    h, ink = browser.js(CANVAS_HASH % element)
    return int(h), float(ink)


def assert_offline(browser: Browser) -> None:
    """Every request the page made stayed on the local file (or inline data)."""
    outside = [u for u in browser.requests() if not u.startswith(("file://", "data:", "blob:", "about:"))]
    assert outside == [], f"requests to other hosts: {outside}"


def state(browser: Browser) -> dict[str, Any]:
    return browser.js("window.linkworkViewer.state()")


def test_hexagon_viewer_slider_moves_the_drawing(browser: Browser, tmp_path: Path) -> None:
    from linkwork.linkages.hedgepeth_rods import deployed_angles

    mech = lw.load("hedgepeth-rods", n=6)  # the hoop that opens from the bundle into the flat hexagon
    path = lw.trace(mech, until=("A", deployed_angles(6)[0]), steps=60)
    page = write_trace_viewer(path, tmp_path / "viewer.html")
    mark = len(browser.events)
    browser.open(page)
    st = state(browser)
    assert st["branch"] == 0 and st["point"] == 0 and st["points"] == 61
    assert st["triangles"] > 0
    h0, ink0 = canvas(browser)
    assert ink0 > 0.01, f"the 3-D view is blank ({ink0:.3%} of its pixels drawn)"
    browser.screenshot(tmp_path / "hexagon-bundle.png")
    # Move the slider as a user would: focus it and press the right arrow 30 times, then End.
    browser.js("document.getElementById('slider').focus()")
    for _ in range(30):
        browser.key("ArrowRight", 39)
    assert state(browser)["point"] == 30
    h1, _ = canvas(browser)
    assert h1 != h0, "the drawing did not change when the slider moved"
    plot0 = canvas(browser, "plot-angles")[0]
    browser.key("End", 35)
    assert state(browser)["point"] == 60
    assert canvas(browser)[0] not in (h0, h1)
    assert canvas(browser, "plot-angles")[0] != plot0, "the plot cursor did not follow the slider"
    shown = browser.js("document.getElementById('stage-caption').textContent")
    assert f"A = {np.degrees(deployed_angles(6)[0]):.2f}°" in shown
    browser.screenshot(tmp_path / "hexagon-deployed.png")
    # Orbit with the mouse.
    box = browser.js(
        "(() => { const r = document.getElementById('scene').getBoundingClientRect(); return [r.x, r.y, r.width, r.height]; })()"
    )
    h2, _ = canvas(browser)
    cx, cy = box[0] + box[2] / 2, box[1] + box[3] / 2
    browser.drag(cx, cy, cx + 120, cy + 40)
    browser.js("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
    assert canvas(browser)[0] != h2, "dragging did not orbit the view"
    assert browser.js("document.getElementById('branch-box').style.display") == "none", (
        "one branch: no selector"
    )
    browser.events[:mark] = []
    assert browser.errors() == []
    assert_offline(browser)


def test_guest_frame_viewer_switches_branches(browser: Browser, tmp_path: Path) -> None:
    path = lw.trace(lw.load("guest-frame"), branches=True, max_steps=6000)
    page = write_trace_viewer(path, tmp_path / "viewer.html")
    assert page.stat().st_size < 5_000_000
    mark = len(browser.events)
    browser.open(page)
    options = browser.js("[...document.getElementById('branch').options].map(o => o.value)")
    assert len(options) == len(path.branches) == 7
    _, ink0 = canvas(browser)
    assert ink0 > 0.01
    # Along branch 0 to its first bifurcation point: the panel offers the branches through it.
    b0 = path.bifurcations[0]
    browser.js(f"window.linkworkViewer.setPoint({b0.step})")
    offers = browser.js("[...document.querySelectorAll('#here button')].map(b => b.textContent)")
    assert any("leaves" in o for o in offers), offers
    # Take one of them, as a user would: click the first offered branch.
    browser.js("document.querySelector('#here button').click()")
    st = state(browser)
    assert st["branch"] != 0
    # Switch branches through the selector, as a user would.
    seen = set()
    for value in ("2", "4", "6"):
        browser.js(
            f"(() => {{ const s = document.getElementById('branch'); s.value = '{value}';"
            " s.dispatchEvent(new Event('change')); })()"
        )
        st = state(browser)
        assert st["branch"] == int(value) and st["point"] == 0
        browser.js(f"window.linkworkViewer.setPoint({st['points'] // 2})")
        seen.add(canvas(browser)[0])
        seen.add(canvas(browser, "plot-sigma")[0])
    assert len(seen) == 6, "switching branches did not change the drawing and the plots"
    browser.js("window.linkworkViewer.setBranch(6, 60)")
    browser.screenshot(tmp_path / "guest-frame-branch-6.png")
    browser.events[:mark] = []
    assert browser.errors() == []
    assert_offline(browser)


def test_play_button_advances_along_the_path(browser: Browser, tmp_path: Path) -> None:
    path = lw.trace(lw.load("bennett"), steps=40, until=("A", 2.0))
    page = write_trace_viewer(path, tmp_path / "viewer.html")
    mark = len(browser.events)
    browser.open(page)
    browser.js("document.getElementById('play').click()")
    browser.js("new Promise(r => setTimeout(r, 400))")
    assert state(browser)["point"] > 0, "play did not advance"
    browser.events[:mark] = []
    assert browser.errors() == []


def test_synthesis_viewer_slider_across_profiles(browser: Browser, tmp_path: Path) -> None:
    from linkwork.data import example
    from linkwork.io.problem import load_problem
    from linkwork.synthesis import synthesize

    result = synthesize(load_problem(example("wing")))
    page = write_synthesis_viewer(result, tmp_path / "viewer.html")
    mark = len(browser.events)
    browser.open(page)
    h0, ink0 = canvas(browser)
    assert ink0 > 0.005
    browser.js("document.getElementById('slider').focus()")
    browser.key("ArrowRight", 39)
    assert browser.js("window.linkworkViewer.state().profile") == 1
    assert canvas(browser)[0] != h0, "the drawing did not change with the profile"
    browser.screenshot(tmp_path / "synthesis-wing.png")
    browser.events[:mark] = []
    assert browser.errors() == []
    assert_offline(browser)


def test_demo_index_shows_every_result_and_its_hexagon_opens_flat(browser: Browser, tmp_path: Path) -> None:
    """The newcomer's path: ``linkwork demo``, open index.html, open the hexagon's viewer, drag it to the end."""
    import csv
    import re

    from typer.testing import CliRunner

    from linkwork.cli import app
    from linkwork.linkages.hedgepeth_rods import deployed_angles

    out = tmp_path / "demo"
    result = CliRunner().invoke(app, ["demo", "--out", str(out)])
    assert result.exit_code == 0, result.output
    index = out / "index.html"
    links = re.findall(r"(?:href|src)='([^']+)'", index.read_text(encoding="utf-8"))
    assert len(links) > 30
    missing = [link for link in links if not (out / link).is_file()]
    assert missing == [], f"index.html links files that are not there: {missing}"
    for section in ("hexagon", "guest-frame", "synthesis-wing", "mechanism-wing"):
        assert any(link.startswith(f"{section}/") for link in links), section
    # The animations: the traced hexagon and the mechanized wing moving through its profiles, also as MP4s.
    from linkwork.viz.animate import find_ffmpeg

    ffmpeg = find_ffmpeg()
    if ffmpeg is not None:
        for movie, frames in (("hexagon/motion.mp4", None), ("mechanism-wing/mechanism.mp4", 2 * 20 - 2)):
            run = subprocess.run(
                [ffmpeg, "-i", str(out / movie), "-map", "0:v:0", "-f", "null", "-"],
                capture_output=True, text=True, check=True,
            )  # fmt: skip
            counted = int(re.findall(r"frame=\s*(\d+)", run.stderr)[-1])
            assert counted > 10 if frames is None else counted == frames, (movie, counted)
    # The hexagon ends on the flat hexagon (the rods' closed form).
    with (out / "hexagon" / "path.csv").open(encoding="utf-8") as f:
        last = list(csv.DictReader(f))[-1]
    inner, outer = np.degrees(deployed_angles(6))
    assert float(last["A"]) == pytest.approx(inner, abs=1e-9)
    assert float(last["B"]) == pytest.approx(outer, abs=1e-9)
    # In the browser: every picture loads, nothing errs, nothing leaves the machine.
    mark = len(browser.events)
    browser.open(index)
    browser.js(
        "Promise.all([...document.images].map(i => i.complete ? 0 : new Promise(r => { i.onload = i.onerror = r; })))"
    )
    broken = browser.js("[...document.images].filter(i => !(i.naturalWidth > 0)).map(i => i.src)")
    assert broken == []
    assert browser.js("document.images.length") >= 10
    browser.screenshot(tmp_path / "demo-index.png")
    viewers = browser.js("[...document.querySelectorAll('a.viewer')].map(a => a.href)")
    assert len(viewers) == 3
    browser.open(out / "hexagon" / "viewer.html")
    browser.js("document.getElementById('slider').focus()")
    browser.key("End", 35)
    shown = browser.js("document.getElementById('stage-caption').textContent")
    assert f"A = {inner:.2f}°" in shown
    browser.screenshot(tmp_path / "demo-hexagon-deployed.png")
    browser.events[:mark] = []
    assert browser.errors() == []
    assert_offline(browser)


def test_mechanism_viewer_opens_fixed_with_the_target_profiles(browser: Browser, tmp_path: Path) -> None:
    from linkwork.io.problem import load_problem
    from linkwork.mechanization import MechanizeOptions, mechanize
    from linkwork.viz.mechanism_viewer import write_mechanism_viewer

    wing = example("wing", "mechanize.toml")
    found = mechanize(lw.synthesize(load_problem(wing)), MechanizeOptions(designs=1))
    page = write_mechanism_viewer(found, tmp_path / "mechanism.html")
    browser.open(page)
    assert browser.js("document.getElementById('centred').checked") is False  # ground fixed, profiles still
    fixed, ink = canvas(browser)
    assert ink > 0.01
    browser.screenshot(tmp_path / "wing-mechanism.png")
    browser.js("document.getElementById('centred').click()")  # the steady view moves: no profiles drawn there
    assert browser.js("document.getElementById('centred').checked") is True
    for _ in range(50):  # the page redraws on its next animation frame
        steady, _ = canvas(browser)
        if steady != fixed:
            break
        time.sleep(0.1)
    assert steady != fixed
    assert browser.errors() == []
    assert_offline(browser)

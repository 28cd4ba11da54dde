"""No markup a user wrote ever runs: hostile names in the trace and synthesis viewers, opened in headless
chromium, stay text (no handler runs, no element is injected) and the page still renders; the SVG outline
parses as XML with the names as text.

Uses the DevTools driver of tests/viz/test_viewer_browser.py; skipped, with the reason, without chromium.
"""

from __future__ import annotations

import importlib.util
import shutil
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import linkwork as lw
from linkwork.io.profiles import write_outline_dxf, write_outline_svg
from linkwork.kinematics.mechanism import Mechanism
from linkwork.linkages.bennett import bennett
from linkwork.synthesis import Problem, synthesize
from linkwork.viz.viewer import write_synthesis_viewer, write_trace_viewer

_spec = importlib.util.spec_from_file_location(
    "linkwork_browser_driver", Path(__file__).resolve().parents[1] / "viz" / "test_viewer_browser.py"
)
assert _spec is not None and _spec.loader is not None
driver: Any = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(driver)

pytestmark = driver.pytestmark

JOINTS = [
    '"><img src=x onerror=window.__pwned=1>',
    "<u>underlined</u>",
    "<!--",
    "</script><script>window.__pwned=2</script>",
]
TITLE = "Bennett \u2028<img src=x onerror=window.__pwned=3> & <!-- [/]"
PROFILES = ['"><img src=x onerror=window.__pwned=4>', "<b>bold</b> &amp;"]

NO_INJECTION = """(() => ({
  pwned: window.__pwned === undefined ? null : window.__pwned,
  injected: document.querySelectorAll('img, u, script:not([type]) ~ script:not([type])').length,
  bold: Array.from(document.querySelectorAll('b')).map((b) => b.textContent),
  text: document.body.textContent,
  title: document.getElementById('title').textContent,
}))()"""


@pytest.fixture(scope="module")
def browser(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    profile = tmp_path_factory.mktemp("chromium-profile")
    b = driver.Browser(profile)
    yield b
    b.close()
    shutil.rmtree(profile, ignore_errors=True)


def test_hostile_joint_names_in_the_trace_viewer_stay_text(browser: Any, tmp_path: Path) -> None:
    base = bennett()
    mech = Mechanism.single_loop(TITLE, JOINTS, base.twists, offsets=base.offsets)
    page = write_trace_viewer(lw.trace(mech, max_steps=60), tmp_path / "viewer.html")
    browser.open(page)
    seen = browser.js(NO_INJECTION)
    assert seen["pwned"] is None and seen["injected"] == 0
    assert seen["title"] == TITLE
    for name in JOINTS:
        assert name in seen["text"]  # the readout shows every name as written
    assert browser.js("window.linkworkViewer.state()")["renders"] > 0  # the script ran and drew
    assert driver.canvas(browser)[1] > 0.01
    assert browser.errors() == []
    driver.assert_offline(browser)


@pytest.fixture(scope="module")
def hostile_synthesis() -> Any:
    lines = (np.array([[0.0, 0.0], [3.0, 0.0]]), np.array([[0.0, 0.0], [4.2, 0.0]]))
    return synthesize(Problem(profiles=lines, piece_length=0.3, design="MC", starts=1, names=tuple(PROFILES)))


def test_hostile_profile_names_in_the_synthesis_viewer_stay_text(
    browser: Any, tmp_path: Path, hostile_synthesis: Any
) -> None:
    page = write_synthesis_viewer(hostile_synthesis, tmp_path / "viewer.html")
    browser.open(page)
    seen = browser.js(NO_INJECTION)
    assert seen["pwned"] is None and seen["injected"] == 0
    assert PROFILES[0] in seen["bold"]  # the profile shown is named in bold, as text
    assert browser.js("window.linkworkViewer.state()")["renders"] > 0
    assert browser.errors() == []


def test_hostile_profile_names_in_the_svg_and_dxf_outlines(tmp_path: Path, hostile_synthesis: Any) -> None:
    import ezdxf

    write_outline_svg(tmp_path / "outline.svg", hostile_synthesis)
    titles = [t.text for t in ET.parse(tmp_path / "outline.svg").iter("{http://www.w3.org/2000/svg}title")]
    assert any(PROFILES[0] in (t or "") for t in titles)
    write_outline_dxf(tmp_path / "outline.dxf", hostile_synthesis)
    layers = [layer.dxf.name for layer in ezdxf.readfile(tmp_path / "outline.dxf").layers]
    assert len({name.casefold() for name in layers}) == len(layers)


def test_names_differing_only_in_case_or_dropped_characters_get_distinct_dxf_layers(tmp_path: Path) -> None:
    """ezdxf refused the second layer of "Wing" and "wing", or of "a/b" and "a:b" (both "a_b")."""
    import ezdxf

    lines = tuple(np.array([[0.0, 0.0], [3.0 + k, 0.0]]) for k in range(4))
    names = ("Wing", "wing", "a/b", "a:b")
    result = synthesize(Problem(profiles=lines, piece_length=0.3, design="MC", starts=1, names=names))
    write_outline_dxf(tmp_path / "outline.dxf", result)
    layers = {layer.dxf.name for layer in ezdxf.readfile(tmp_path / "outline.dxf").layers}
    assert {"Wing-chain", "wing_2-chain", "a_b-chain", "a_b_2-chain"} <= layers  # linkwork.names.dxf_layers

"""The viewers' pages: one self-contained HTML file around a viewer's data, that a browser opens offline.

A page is the shared shell ``viewer_assets/page.html`` (head, title, footer, the data and the script) around one
viewer's body (its panel, controls and plots), with the shared play button and slider of ``player.html``; the
style and the scripts are inlined, and the data is JSON with the bulky arrays as little-endian base64
(:func:`unpack` reads them back). The page fetches nothing, from no host.
"""

from __future__ import annotations

import base64
import json
import re
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from linkwork.names import html_text

__all__ = ["DATA_ID", "script_json", "unpack"]

DATA_ID = "linkwork-data"
"""The ``id`` of the ``<script type="application/json">`` element holding a viewer's data."""


def packed_array(values: Any, dtype: str) -> dict[str, Any]:
    """A numpy array as ``{"dtype", "shape", "b64"}``, little-endian, for ``decode`` in the page's script."""
    arr = np.ascontiguousarray(np.asarray(values), dtype=np.dtype(dtype).newbyteorder("<"))
    return {"dtype": dtype, "shape": list(arr.shape), "b64": base64.b64encode(arr.tobytes()).decode("ascii")}


def unpack(entry: dict[str, Any]) -> NDArray[Any]:
    """Inverse of the page's packing: the numpy array of a ``{"dtype", "shape", "b64"}`` entry (for tests)."""
    raw = base64.b64decode(entry["b64"])
    return np.frombuffer(raw, dtype=np.dtype(entry["dtype"]).newbyteorder("<")).reshape(entry["shape"])


def _asset(name: str) -> str:
    return (resources.files("linkwork.viz") / "viewer_assets" / name).read_text(encoding="utf-8")


@dataclass(frozen=True)
class ViewerAssets:
    """One viewer's assets: its ``body`` (panel, controls and plots inside the shared ``page.html``), its scripts
    in load order, and the accessible name of its slider (inside the shared ``player.html``)."""

    body: str
    scripts: tuple[str, ...]
    slider: str


def page_html(viewer: ViewerAssets, data: dict[str, Any]) -> str:
    """A self-contained page: the shared shell ``page.html`` (head, title, footer, data, script) around the
    viewer's body, its play button and slider from ``player.html``; then ``{{TITLE}}`` (``data["title"]``),
    ``{{CSS}}``, ``{{DATA}}``, ``{{JS}}`` and the rest filled in one pass."""
    from linkwork.version import __version__

    values = {
        "TITLE": html_text(data["title"]),
        "CSS": _asset("viewer.css"),
        "DATA": script_json(data),
        "JS": "\n".join(_asset(s) for s in viewer.scripts).replace("</script", "<\\/script"),
        "VERSION": __version__,
        "SLIDER": viewer.slider,
    }
    body = _asset(viewer.body).rstrip("\n").replace("{{PLAYER}}", _asset("player.html").rstrip("\n"))
    shell = _asset("page.html").replace("{{BODY}}", body)
    return re.sub(r"\{\{([A-Z]+)\}\}", lambda m: values[m.group(1)], shell)


#: Characters of JSON text that must not appear raw inside an HTML <script> element: "<" and ">" could open
#: "</script>" or "<!--" (which changes how the element ends), "&" for symmetry with HTML escaping, and U+2028
#: / U+2029, which older JavaScript parsers treat as line breaks. Each is written as its JSON \\u escape, so the
#: data parse back to the same strings.
_SCRIPT_UNSAFE = {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026", "\u2028": "\\u2028", "\u2029": "\\u2029"}


def script_json(data: Any) -> str:
    """``data`` as JSON text safe to embed inside ``<script type="application/json">`` (no NaN or inf)."""
    payload = json.dumps(data, separators=(",", ":"), allow_nan=False)
    return re.sub("[<>&\u2028\u2029]", lambda m: _SCRIPT_UNSAFE[m.group(0)], payload)


def write_page(file: str | Path, text: str) -> Path:
    file = Path(file)
    file.parent.mkdir(parents=True, exist_ok=True)
    file.write_text(text, encoding="utf-8")
    return file

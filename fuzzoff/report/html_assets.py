"""The scripts and styles written into every HTML report, and the page's security policy.

The page runs exactly two scripts, both inline: uPlot (vendored, MIT) and ``timeline.js``. The
Content-Security-Policy allows those two by their SHA-256 and nothing else: no other script, no
request of any kind (``default-src 'none'``), so text from a recording could not run code even
if it escaped its escaping. The plot data are ``application/json`` blocks, which never run.
"""

from __future__ import annotations

import base64
import functools
import hashlib
from importlib.resources import files

CSP = (
    "default-src 'none'; style-src 'unsafe-inline'; img-src data:; "
    "base-uri 'none'; form-action 'none'"
)
"""The policy of a page with no script: nothing but inline styles (also the base of the
report's own policy)."""


def _text(name: str) -> str:
    return files("fuzzoff.report").joinpath(*name.split("/")).read_text(encoding="utf-8")


@functools.cache
def scripts() -> tuple[str, str]:
    """uPlot with its licence in a comment, and the report's own script."""
    licence = _text("vendor/uPlot.LICENSE").replace("*/", "* /")
    code = _text("vendor/uPlot.iife.min.js")
    out = f"/* uPlot 1.6.32, vendored unchanged.\n{licence}*/\n{code}", _text("timeline.js")
    for script in out:  # inline in a <script> element, such text would end it early
        lowered = script.lower()
        assert "</script" not in lowered and "<!--" not in lowered
    return out


@functools.cache
def uplot_css() -> str:
    return _text("vendor/uPlot.min.css")


def _sha256(script: str) -> str:
    digest = hashlib.sha256(script.encode("utf-8")).digest()
    return f"'sha256-{base64.b64encode(digest).decode('ascii')}'"


@functools.cache
def report_csp() -> str:
    """``CSP`` plus the two inline scripts, each allowed by its hash."""
    hashes = " ".join(_sha256(s) for s in scripts())
    return f"{CSP}; script-src {hashes}"

"""The browser tests' helpers: no browser (skip, or fail in CI), and reading a page in the
browser: its console errors, and text behind shadow roots."""

import os
import time

import pytest


def no_browser(reason: str):
    """Skip with ``reason``, or fail in CI, where the browser must be there."""
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(f"{reason}; in CI .ci/run installs chromium and chromium-driver")
    pytest.skip(reason)


#: JavaScript: every element matching ``arguments[0]``, in the document and in every shadow
#: root under it (Bokeh and Panel draw into shadow roots), as [text, dataset] pairs.
FIND_DEEP = """
const selector = arguments[0];
const found = [];
(function visit(root) {
    root.querySelectorAll(selector).forEach(e => found.push(e));
    root.querySelectorAll('*').forEach(e => { if (e.shadowRoot) visit(e.shadowRoot); });
})(document);
return found.map(e => [e.textContent, Object.assign({}, e.dataset)]);
"""

#: JavaScript: for every canvas in the page (shadow roots included), its size and how many of
#: its pixels are neither transparent nor white.
CANVAS_INK = """
const canvases = [];
(function visit(root) {
    root.querySelectorAll('canvas').forEach(c => canvases.push(c));
    root.querySelectorAll('*').forEach(e => { if (e.shadowRoot) visit(e.shadowRoot); });
})(document);
return canvases.map(c => {
    if (c.width === 0 || c.height === 0) return [0, 0, 0];
    const pixels = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let ink = 0;
    for (let i = 0; i < pixels.length; i += 4) {
        const white = pixels[i] > 245 && pixels[i + 1] > 245 && pixels[i + 2] > 245;
        if (pixels[i + 3] > 0 && !white) ink += 1;
    }
    return [c.width, c.height, ink];
});
"""


def deep_texts(driver, selector: str) -> list:
    """[text, data attributes] of every element matching ``selector``, shadow roots included."""
    return driver.execute_script(FIND_DEEP, selector)


def console_errors(driver) -> list:
    """The browser console's errors since it was last read."""
    return [entry for entry in driver.get_log("browser") if entry["level"] == "SEVERE"]


def wait_for(condition, timeout: float = 30.0, step: float = 0.1):
    """Call ``condition()`` until it returns something true; return it (or fail after
    ``timeout`` s with the last value)."""
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"not reached within {timeout} s; last value {value!r}")
        time.sleep(step)

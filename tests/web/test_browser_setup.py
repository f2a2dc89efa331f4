"""Where no browser can be installed the browser tests skip, saying why; in CI they fail."""

import pytest

from tests.web.pages import no_browser


def test_without_a_browser_ci_fails_and_elsewhere_skips(monkeypatch):
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match=r"no chromium; in CI \.ci/run installs"):
        no_browser("no chromium")
    monkeypatch.delenv("CI")
    with pytest.raises(pytest.skip.Exception, match="no chromium"):
        no_browser("no chromium")

"""Pages for a browser: a test's self-contained HTML report (:mod:`ecofmaps.web.report`) and a
live explorer of the model (:mod:`ecofmaps.web.explorer`, served by :mod:`ecofmaps.web.server`).
Those need the extra ``web`` (Bokeh, Panel: ``pip install "ecofmaps[web]"``); this does not."""

from __future__ import annotations

import importlib.util

from ecofmaps._nomenclature import axis_label

__all__ = ["INSTALL_WEB", "missing_web_packages"]

#: The one line that tells how to install what the pages need.
INSTALL_WEB = 'the web pages need Bokeh and Panel: pip install "ecofmaps[web]"'
#: The packages of the extra ``web``, by import name.
_WEB_PACKAGES = ("bokeh", "panel")


def missing_web_packages(packages=_WEB_PACKAGES) -> list[str]:
    """The packages of the extra ``web`` that cannot be imported here.

    Parameters
    ----------
    packages : sequence of str
        Import names to look for; by default those of the extra ``web``.

    Returns
    -------
    missing : list of str
        Those not installed, in the order given; empty when the pages can be made.

    Examples
    --------
    >>> missing_web_packages(["json", "no_such_package_for_ecofmaps"])
    ['no_such_package_for_ecofmaps']
    """
    return [name for name in packages if importlib.util.find_spec(name) is None]


def quantity_plot(title: str, x: str, y: str, **options):
    """A Bokeh plot with the pages' tools, its axes labelled by quantities ``x`` and ``y``."""
    from bokeh.plotting import figure

    labels = dict(x_axis_label=axis_label(x, plain=True), y_axis_label=axis_label(y, plain=True))
    return figure(title=title, tools="pan,box_zoom,wheel_zoom,reset,save", **labels, **options)

"""The explorer's local web server (``ecofmaps explore``): the page of
:mod:`ecofmaps.web.explorer` at 127.0.0.1, answered only to local pages."""

from __future__ import annotations

import asyncio
import re
import signal
import urllib.parse
import webbrowser

from panel.io.server import get_server
from tornado.routing import Matcher, Rule
from tornado.web import RequestHandler

from ecofmaps._interrupts import check_interrupted, interrupted_waiting
from ecofmaps.units import TEXT_LIMIT
from ecofmaps.web.explorer import explorer_page, warm_up

# The longest query value let through to Panel, whose reading of the query fails on an
# integer of more than 4300 digits; a longer one is cut to one character over TEXT_LIMIT.
_QUERY_LIMIT = 1000

#: The hosts whose pages the explorer answers (with its port); others get 403. Not [::1]: the
#: server listens on 127.0.0.1 only, and Panel cannot read a bracketed Host (an HTTP 500).
LOCAL_HOSTS = ("127.0.0.1", "localhost")


class _Foreign(Matcher):
    """Matches a request whose Host, or Origin if it has one, is not an allowed host."""

    def __init__(self, hosts: set):
        self.hosts = hosts

    def match(self, request):
        host = request.headers.get("Host", "").lower()
        origin = request.headers.get("Origin")
        if origin is not None:
            parts = urllib.parse.urlsplit(origin.lower())
            origin = parts.netloc if parts.scheme == "http" else ""
        foreign = host not in self.hosts or (origin is not None and origin not in self.hosts)
        return {} if foreign else None


class _Forbidden(RequestHandler):
    """403 for every request it gets, with the way to allow another host."""

    def initialize(self, url: str):
        self.url = url

    def prepare(self):
        self.set_status(403)
        self.set_header("Content-Type", "text/plain; charset=utf-8")
        self.finish(
            f"403 Forbidden: this explorer answers the pages of {self.url} only (the request's "
            "Host or Origin is another). To open it from another host, start it with "
            "--allow-origin HOST[:PORT].\n"
        )


class _LongQuery(Matcher):
    def match(self, request):
        pairs = urllib.parse.parse_qsl(request.query, keep_blank_values=True)
        return {} if any(len(value) > _QUERY_LIMIT for _, value in pairs) else None


class _CutQuery(RequestHandler):
    """See Other: the page with each overlong query value cut (Panel fails on a huge number)."""

    def prepare(self):
        pairs = urllib.parse.parse_qsl(self.request.query, keep_blank_values=True)
        cut = [(key, v if len(v) <= _QUERY_LIMIT else v[: TEXT_LIMIT + 1]) for key, v in pairs]
        self.redirect(f"{self.request.path}?{urllib.parse.urlencode(cut)}", status=303)


def serve_explorer(port: int, *, open_browser: bool = True, announce=print, allow_origin=()):
    """Serve the explorer at ``http://127.0.0.1:<port>/`` until Ctrl-C or SIGTERM, its address
    ``announce``d once it listens (OSError if it cannot); a Host or Origin not in
    :data:`LOCAL_HOSTS` or ``allow_origin`` (``host[:port]``, at ``port`` if none) gets a 403."""
    previous = {number: signal.getsignal(number) for number in (signal.SIGINT, signal.SIGTERM)}
    ours = [number for number, before in previous.items() if before not in (signal.SIG_IGN, None)]
    url = f"http://127.0.0.1:{port}/"
    hosts = {f"{host}:{port}" for host in LOCAL_HOSTS}  # and each allowed, at port if none
    for entry in (entry.strip().lower() for entry in allow_origin):
        hosts.add(entry if re.fullmatch(r".*:\d+", entry) else f"{entry}:{port}")
    # Bokeh cannot parse a bracketed host ([::1]:port); _Foreign checks every request.
    origins = sorted(h for h in hosts if not h.startswith("["))
    options = dict(
        port=port, address="127.0.0.1", websocket_origin=origins, title="ecofmaps explorer"
    )
    server = get_server({"/": explorer_page}, show=False, start=False, **options)
    signal.signal(signal.SIGINT, previous[signal.SIGINT])  # Panel's would stop at once
    # Before Bokeh's and Panel's routes, for every path: Tornado's documented rule router.
    server._tornado.default_router.rules[:0] = [
        Rule(_Foreign(hosts), _Forbidden, {"url": url}),
        Rule(_LongQuery(), _CutQuery),
    ]
    loop = server.io_loop

    def stop(signum, frame):  # the loop stops as soon as it runs (at once if it runs)
        loop.asyncio_loop.call_soon_threadsafe(loop.stop)

    try:
        interrupted_waiting(warm_up)  # the port is taken: a page asked for meanwhile waits
        server.start()
        for number in ours:  # a signal ignored (Ctrl-C in a background job) stays ignored
            signal.signal(number, stop)
        check_interrupted()  # or while the model compiled: the URL is never given
        announce(f"ecofmaps explorer at {url} (Ctrl-C stops it)")
        if open_browser:
            loop.add_callback(webbrowser.open, url)
        loop.start()
    finally:
        for number in ours:
            signal.signal(number, previous[number])
        server.stop()
        # What is still pending on the event loop (the sessions' tasks) cancelled.
        pending = [task for task in asyncio.all_tasks(loop.asyncio_loop) if not task.done()]
        for task in pending:
            task.cancel()
        if pending and not loop.asyncio_loop.is_closed():
            loop.asyncio_loop.run_until_complete(asyncio.gather(*pending, return_exceptions=True))

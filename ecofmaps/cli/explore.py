"""``ecofmaps explore``: a live explorer of the model in the browser, served on this machine."""

from __future__ import annotations

import argparse
import functools
import importlib

from ecofmaps._interrupts import interrupted_waiting
from ecofmaps.cli.common import CommandError, option_adder
from ecofmaps.web import INSTALL_WEB, missing_web_packages

_HELP = {
    "--port": "the port to listen on (default %(default)s)",
    "--no-browser": "do not open the page in a browser",
    "--allow-origin": "also answer this host (a tunnel's or proxy's; without a port, --port's), "
    "repeatable; by default only 127.0.0.1 and localhost at --port, others (Host, Origin) get 403",
}


def _port(text: str) -> int:
    """An argparse ``type``: a TCP port, 1 to 65535."""
    try:
        port = int(text)
    except ValueError:
        port = 0
    if not 1 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"{text!r} is not a port: give a number from 1 to 65535")
    return port


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "explore",
        help="explore the model in the browser: δ*, E_d, μ_E/μ, the loop, the map, a correction",
        description="Serve a page at http://127.0.0.1:PORT/ (this machine only): type the "
        "amplitude, load, rig stiffness, contact CoF and groove aspect ratio with units (50um, "
        "450N, 35MN/m) to see the slip amplitude, dissipated energy, μ_E/μ, the steady loop, the "
        "map of μ_E/μ over S/P and z_o/x_o, and the contact CoF behind an ECoF; the URL keeps the "
        'inputs. Ctrl-C stops it. Needs pip install "ecofmaps[web]".',
    )
    option = option_adder(parser, _HELP)
    option("--port", type=_port, default=5006, metavar="N")
    option("--no-browser", action="store_true")
    option("--allow-origin", action="append", default=[], metavar="HOST[:PORT]")


def run(args) -> int:
    if missing_web_packages():
        raise CommandError(INSTALL_WEB)
    # Panel and Bokeh load in a thread: a stop while they load (seconds) is acted on at once
    server = interrupted_waiting(functools.partial(importlib.import_module, "ecofmaps.web.server"))
    try:
        server.serve_explorer(
            args.port,
            open_browser=not args.no_browser,
            announce=functools.partial(print, flush=True),  # the address at once, also in a pipe
            allow_origin=args.allow_origin,
        )
    except OSError as error:
        raise CommandError(
            f"cannot listen on 127.0.0.1:{args.port} ({error.strerror or error}): choose "
            "another --port"
        ) from None
    print("ecofmaps explorer stopped")
    return 0

"""The live explorer (ecofmaps explore, ecofmaps.web.explorer): its inputs, and the server in a
real browser: the model's numbers for parameters in the URL, an input typed, a clean stop."""

import html
import http.client
import math
import os
import selectors
import signal
import socket
import subprocess
import sys
import urllib.parse

import panel as pn
import pytest

import ecofmaps
from ecofmaps.cli import explore
from ecofmaps.figures.style import ECOF_RATIO_LEVELS
from ecofmaps.units import DOMAIN, TEXT_LIMIT
from ecofmaps.web import explorer
from ecofmaps.web.explorer import (
    bare_number_warnings,
    explorer_page,
    map_window,
    parameter_value,
)
from tests.cli.commands import run
from tests.web.pages import CANVAS_INK, console_errors, deep_texts, wait_for

#: Two views, as a user shares them: the paper's Example 2 with units, another in SI numbers.
VIEWS = {
    "example 2": {"amplitude": "50um", "load": "450N", "stiffness": "35MN/m", "mu": "0.8",
                  "aspect_ratio": "0.2"},
    "SI numbers": {"amplitude": "2.5e-5", "load": "300", "stiffness": "2e7", "mu": "0.6",
                   "aspect_ratio": "0.3"},
}  # fmt: skip


def expected_ratio(view: dict) -> str:
    """μ_E/μ of ``ecofmaps.energy_cof`` at a view, to 3 decimals as the page shows it."""
    values = [parameter_value(key, view[key]) for key in VIEWS["example 2"]]
    return f"{float(ecofmaps.energy_cof(*values)) / values[3]:.3f}"


def test_inputs_are_read_with_units_or_in_si():
    assert parameter_value("amplitude", "50um") == pytest.approx(50e-6, rel=1e-15)
    assert parameter_value("amplitude", "5e-5") == 5e-5
    assert parameter_value("stiffness", "inf") == math.inf
    with pytest.raises(ValueError, match="Normal load P: '-3N' is out of range"):
        parameter_value("load", "-3N")
    with pytest.raises(ValueError, match="Rig stiffness S"):
        parameter_value("stiffness", "35um")
    assert math.copysign(1.0, parameter_value("aspect_ratio", "-0")) == 1.0  # shown as 0
    assert bare_number_warnings({"amplitude": "9" * 5000}) == []  # refused, not also warned of
    with pytest.raises(ValueError) as refused:
        parameter_value("aspect_ratio", "1e7")
    assert str(refused.value).endswith("beyond the model's domain, 0 to 1e+06")  # a ratio: no unit


#: Hostile query values: (key, text, what the page's message says).
HOSTILE = [
    ("aspect_ratio", "1e308", "Groove aspect ratio z_o/x_o: '1e308' is beyond the model's domain"),
    ("stiffness", "1.7e308", "Rig stiffness S: '1.7e308' is beyond the model's domain, 0.001 to"),
    ("stiffness", "1e308MN/m", "Rig stiffness S: '1e308MN/m' is beyond the largest number"),
    (
        "amplitude",
        "1" * 5000,
        f"Displacement amplitude Δ*: cannot read '{'1' * TEXT_LIMIT}'... as a length: more than "
        f"{TEXT_LIMIT} characters",
    ),
    ("load", "9**9**9 N", "Normal load P: cannot read '9**9**9 N' as a force: give a number"),
    ("load", "10**400 N", "Normal load P: cannot read '10**400 N' as a force: give a number"),
    ("mu", "nan", "Contact CoF μ: 'nan' is out of range: 0 < μ < inf"),
]


@pytest.mark.parametrize(("key", "text", "message"), HOSTILE)
def test_hostile_inputs_are_refused_before_any_arithmetic(key, text, message):
    with pytest.raises(ValueError) as refused:
        parameter_value(key, text)
    assert str(refused.value).startswith(message)


def test_the_map_window_holds_the_point():
    assert map_window(35e6 / 450, 0.2) == (20e3, 200e3, 0.4)  # Figure 11's
    low, high, deepest = map_window(1.5e6, 0.9)
    assert low <= 1.5e6 / 1.1 and high >= 1.5e6 * 1.1 and deepest >= 0.9 * 1.1
    assert map_window(3e3, 0.0)[0] <= 3e3 * 0.9
    assert map_window(math.inf, 0.1) == (20e3, 200e3, 0.4)  # a rigid rig is not marked


def test_without_the_web_extra_the_command_says_how_to_install_it(capsys, monkeypatch):
    monkeypatch.setattr(explore, "missing_web_packages", lambda: ["panel"])
    status, out, err = run(capsys, "explore", "--no-browser")
    assert status == 2 and out == ""
    assert (
        err == 'ecofmaps: error: the web pages need Bokeh and Panel: pip install "ecofmaps[web]"\n'
    )


@pytest.mark.parametrize("port", ["0", "70000", "http"])
def test_a_bad_port_is_named(capsys, port):
    status, _, err = run(capsys, "explore", "--port", port)
    assert status == 2 and f"{port!r} is not a port" in err and err.count("\n") == 1


def test_a_port_in_use_is_one_line(capsys):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        status, _, err = run(capsys, "explore", "--port", port, "--no-browser")
    assert status == 2 and err.count("\n") == 1
    assert f"cannot listen on 127.0.0.1:{port}" in err and "choose another --port" in err


def test_a_failure_of_the_warm_up_is_the_commands(capsys, monkeypatch):
    """The warm-up runs in a thread while the command waits: its error comes back here."""
    from ecofmaps.web import server

    def fails():
        raise ValueError("the model would not compile")

    monkeypatch.setattr(server, "warm_up", fails)
    status, out, err = run(capsys, "explore", "--no-browser", "--port", free_port())
    assert (status, out, err) == (2, "", "ecofmaps: error: the model would not compile\n")


# --- the server, in the browser ---------------------------------------------------------------


def free_port() -> int:
    """A port nobody listens on now."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@pytest.fixture(scope="module")
def started():
    """``ecofmaps explore`` on a free port, in a subprocess: (process, its address)."""
    port = free_port()
    process = subprocess.Popen(
        [sys.executable, "-m", "ecofmaps.cli", "explore", "--port", str(port), "--no-browser"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    yield process, f"http://127.0.0.1:{port}/"
    if process.poll() is None:
        process.kill()
        process.communicate()


@pytest.fixture(scope="module")
def listening(started):
    """The explorer once it listens."""
    process, url = started
    with selectors.DefaultSelector() as waiting:
        waiting.register(process.stdout, selectors.EVENT_READ)
        ready = waiting.select(timeout=180)
    line = process.stdout.readline() if ready else ""
    if url not in line:
        process.kill()
        pytest.fail(f"the explorer did not start: {line!r} {process.communicate()[1]!r}")
    return process, url


@pytest.fixture(scope="module")
def server(started, browser, listening):
    """The explorer once it listens (the browser starts while it compiles the model)."""
    return listening


def shown_values(driver) -> dict:
    """The model's numbers the page shows, by quantity."""
    return {data["quantity"]: text for text, data in deep_texts(driver, ".ecofmaps-value")}


@pytest.mark.parametrize("view", list(VIEWS))
def test_the_page_shows_the_model_for_the_parameters_in_its_url(browser, server, view):
    _, url = server
    browser.get(url + "?" + urllib.parse.urlencode(VIEWS[view]))
    wanted = expected_ratio(VIEWS[view])
    shown = wait_for(
        lambda: shown_values(browser).get("ecof_ratio") == wanted and shown_values(browser)
    )
    assert shown["ecof_ratio"] == wanted
    values = [parameter_value(key, VIEWS[view][key]) for key in VIEWS["example 2"]]
    assert shown["slip_amplitude"] == f"{float(ecofmaps.slip_amplitude(*values)) * 1e6:.3f}"
    assert shown["dissipated_energy"] == f"{float(ecofmaps.dissipated_energy(*values)) * 1e3:.3f}"
    mu = float(ecofmaps.correct_ecof(0.83, *values[:3], aspect_ratio=values[4]))
    assert shown["mu_corrected"] == f"{mu:.3f}"
    wait_for(lambda: len([c for c in browser.execute_script(CANVAS_INK) if c[2] > 1000]) >= 2)
    assert console_errors(browser) == []


def test_a_typed_input_updates_the_page_and_its_url(browser, server):
    _, url = server
    view = VIEWS["SI numbers"]
    browser.get(url + "?" + urllib.parse.urlencode(view))
    wait_for(lambda: shown_values(browser).get("ecof_ratio") == expected_ratio(view))
    typed = browser.execute_script(
        """
        const inputs = [];
        (function visit(root) {
            root.querySelectorAll('input').forEach(e => inputs.push(e));
            root.querySelectorAll('*').forEach(e => { if (e.shadowRoot) visit(e.shadowRoot); });
        })(document);
        const mu = inputs.find(e => e.value === '0.6');
        mu.value = '0.7';
        mu.dispatchEvent(new Event('change', {bubbles: true}));
        return true;
        """
    )
    assert typed
    changed = dict(view, mu="0.7")
    wait_for(lambda: shown_values(browser).get("ecof_ratio") == expected_ratio(changed))
    wait_for(lambda: "mu=0.7" in browser.current_url)
    assert console_errors(browser) == []


def answer(url: str, target: str, headers: dict) -> tuple:
    """(status, Location header) of a GET of ``target`` at the server, with ``headers``."""
    port = urllib.parse.urlsplit(url).port
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=60)
    try:
        connection.request("GET", target, headers=headers)
        response = connection.getresponse()
        response.read()
        return response.status, response.getheader("Location")
    finally:
        connection.close()


@pytest.mark.slow
def test_only_local_pages_are_answered(listening):
    """Host and Origin of every request, page and websocket alike; 403 for another's."""
    _, url = listening
    port = urllib.parse.urlsplit(url).port
    local = {"Host": f"localhost:{port}"}
    assert answer(url, "/", local)[0] == 200
    assert answer(url, "/", {"Host": f"127.0.0.1:{port}", "Origin": url.rstrip("/")})[0] == 200
    foreign = [
        {"Host": f"evil.example:{port}", "Origin": "http://evil.example"},
        {"Host": f"evil.example:{port}"},  # a DNS rebinding
        dict(local, Origin="http://evil.example"),
        dict(local, Origin="null"),
        {"Host": f"localhost:{port + 1}"},
        {"Host": f"[::1]:{port}"},  # not listened on; Panel cannot read it (was a 500)
    ]
    for headers in foreign:
        for target in ("/?mu=0.7", "/ws", "/static/js/bokeh.min.js"):
            assert answer(url, target, headers)[0] == 403, (headers, target)


@pytest.mark.slow
def test_a_huge_query_value_is_cut_before_panel_reads_it(listening):
    _, url = listening
    port = urllib.parse.urlsplit(url).port
    status, location = answer(
        url, "/?amplitude=" + "1" * 5000 + "&mu=0.7", {"Host": f"127.0.0.1:{port}"}
    )
    assert status == 303
    assert location == "/?amplitude=" + "1" * (TEXT_LIMIT + 1) + "&mu=0.7"


@pytest.mark.parametrize(("key", "text", "message"), [h for h in HOSTILE if h[0] != "load"])
def test_a_hostile_query_is_a_message_on_the_page(browser, server, key, text, message):
    _, url = server
    browser.get(url + "?" + urllib.parse.urlencode({key: text, "load": "1N"}))
    wait_for(lambda: any(message in t for t, _ in deep_texts(browser, "p")))
    assert console_errors(browser) == []


def test_a_bare_amplitude_is_warned_on_the_page(browser, server):
    _, url = server
    browser.get(url + "?" + urllib.parse.urlencode(dict(VIEWS["example 2"], amplitude="50")))
    warning = "Displacement amplitude Δ*: 50 is 50 m; did you mean 50um?"
    wait_for(lambda: any(warning in text for text, _ in deep_texts(browser, "p")))
    assert console_errors(browser) == []


def test_nothing_is_written_to_disk_per_page(browser, server):
    cache = os.environ["ECOFMAPS_CACHE"]
    before = sorted(os.walk(cache))
    _, url = server
    for mu in ("0.55", "0.65"):
        view = dict(VIEWS["example 2"], mu=mu)
        browser.get(url + "?" + urllib.parse.urlencode(view))
        wait_for(lambda view=view: shown_values(browser).get("ecof_ratio") == expected_ratio(view))
    assert sorted(os.walk(cache)) == before


@pytest.mark.slow
def test_sigterm_stops_it_cleanly(listening):
    """Last of the module: the server stops on SIGTERM, exit 0, no traceback."""
    process, _ = listening
    process.send_signal(signal.SIGTERM)
    out, err = process.communicate(timeout=60)
    assert process.returncode == 0, err
    assert "Traceback" not in err and "Traceback" not in out
    assert "ecofmaps explorer stopped" in out


#: ``ecofmaps explore`` whose start-up (Panel's import, or the model's compiling) gets a signal
#: (sent by the process itself) and then never ends, as XLA compiling does not for seconds: a
#: call that returns to Python, where the handler runs, only when it is done.
SIGNALLED_IN_START_UP = """
import os, signal, sys, threading, types
from ecofmaps.cli import explore
from ecofmaps.cli.main import console
from ecofmaps.web import server
def endless(*args):
    os.kill(os.getpid(), signal.Signals[os.environ["SENT"]])
    threading.Event().wait()
if sys.argv.pop(1) == "import":
    explore.importlib = types.SimpleNamespace(import_module=endless)
else:
    server.warm_up = endless
console()
"""


@pytest.mark.parametrize("step", ["import", "warm_up"])
@pytest.mark.parametrize(("sent", "status"), [("SIGTERM", 143), ("SIGINT", 130)])
def test_a_stop_during_the_start_up_gives_no_address(sent, status, step):
    """The signal comes before the server answers: acted on without waiting for the step to
    end; one line, the run's stop status, no URL."""
    script = [sys.executable, "-c", SIGNALLED_IN_START_UP, step]
    command = [*script, "explore", "--no-browser", "--port", str(free_port())]
    environment = {**os.environ, "SENT": sent}
    done = subprocess.run(command, capture_output=True, text=True, timeout=120, env=environment)
    words = "terminated (SIGTERM)" if sent == "SIGTERM" else "interrupted"
    assert (done.returncode, done.stdout) == (status, "")
    assert done.stderr == f"ecofmaps: {words}; no output was left half written\n"


def test_the_page_follows_its_inputs():
    """The page's callbacks, without a server: numbers, no gross slip, a rigid rig, bad input."""
    page = explorer_page()
    inputs = {widget.label: widget for widget in page.select(pn.widgets.TextInput)}

    def shown():
        return " ".join(str(pane.object) for pane in page.select(pn.pane.HTML))

    assert (
        "data-quantity='ecof_ratio' data-unit=''>1.038<" in shown()
    )  # Example 2: about 4 % above μ
    inputs["Displacement amplitude Δ*"].value = "5um"  # μP/S = 10.3 µm > Δ*
    assert (
        "No gross slip" in shown()
        and "data-quantity='ecof_ratio' data-unit=''>undefined<" in shown()
    )
    inputs["Displacement amplitude Δ*"].value = "50um"
    inputs["Rig stiffness S"].value = "inf"
    rigid = float(ecofmaps.energy_cof(50e-6, 450.0, math.inf, 0.8, 0.2)) / 0.8
    assert f"data-quantity='ecof_ratio' data-unit=''>{rigid:.3f}<" in shown()
    inputs["Normal load P"].value = "-3N"
    assert "Normal load P: &#x27;-3N&#x27; is out of range" in shown()
    inputs["Normal load P"].value = "9**9**9 N"  # refused at once: pint evaluates nothing
    assert "Normal load P: cannot read &#x27;9**9**9 N&#x27; as a force" in shown()
    inputs["Normal load P"].value = "1N"
    inputs["Rig stiffness S"].value = "1.7e308"
    assert "Rig stiffness S: &#x27;1.7e308&#x27; is beyond the model&#x27;s domain" in shown()


def test_the_page_takes_the_models_domain():
    """Each input at either bound of ecofmaps.units.DOMAIN (the command line's and the API's):
    the point shown, map and loop too; a tenth beyond a bound: refused, naming it."""
    page = explorer_page()
    inputs = {widget.label: widget for widget in page.select(pn.widgets.TextInput)}
    message = page.objects[1]
    for key, (name, label, default) in explorer.INPUTS.items():
        low, high = DOMAIN[name]
        for value in (low, high):
            inputs[label].value = repr(value)
            assert message.object == "", (key, value, message.object)
        for value in (high * 1.1, low * 0.9):
            if value != low:  # a lower bound of 0 is the rule's (z_o/x_o >= 0)
                inputs[label].value = repr(value)
                said = f"{label}: '{value!r}' is beyond the model's domain, {low:g} to {high:g}"
                assert said in html.unescape(message.object), (key, message.object)
        inputs[label].value = default
    assert message.object == ""


def test_a_bare_number_implausible_in_si_is_warned_with_the_unit_meant():
    """A warning beside the result (stiffness) or the refusal (amplitude), each value with its
    unit; the warning goes once the unit is typed."""
    page = explorer_page()
    inputs = {widget.label: widget for widget in page.select(pn.widgets.TextInput)}

    def shown():
        return " ".join(str(pane.object) for pane in page.select(pn.pane.HTML))

    inputs["Rig stiffness S"].value = "35"
    assert "Rig stiffness S: 35 is 35 N/m; did you mean 35MN/m?" in shown()
    assert "S = 3.5e-05 MN/m" in shown()  # computed, as read
    assert "data-quantity='slip_amplitude' data-unit='µm'>" in shown()
    inputs["Rig stiffness S"].value = "35MN/m"
    assert "did you mean" not in shown()
    inputs["Displacement amplitude Δ*"].value = "50"  # in the domain: computed as read
    assert "Displacement amplitude Δ*: 50 is 50 m; did you mean 50um?" in shown()
    assert "Δ* = 5e+07 µm" in shown() and page.objects[1].object == ""


def map_of(page):
    """The page's map: its figure, by the names of its renderers."""
    plot = page.select(pn.pane.Bokeh)[1].object
    return plot, {name: plot.select_one({"name": name}) for name in
                  ("bands", "lines", "labels", "no_gross_slip")}  # fmt: skip


def test_the_map_is_labelled_contours_with_no_gross_slip_hatched():
    """Figure 11's levels, each line drawn labelled; the no-gross-slip area hatched and said."""
    page = explorer_page()
    plot, parts = map_of(page)
    labels = parts["labels"].data_source.data
    assert labels["text"] == [f"{level:.2f}" for level in ECOF_RATIO_LEVELS if level <= 1.20]
    assert list(parts["lines"].levels) == list(ECOF_RATIO_LEVELS)
    stuck = parts["no_gross_slip"]
    assert stuck.fill_renderer.data_source.data["xs"] == [[]]  # Example 2: gross slip all over
    assert stuck.fill_renderer.glyph.hatch_pattern == "/"
    legend = [item.label.value for item in plot.legend[0].items]
    assert "no gross slip (μP/S ≥ Δ*): μ_E undefined" in legend
    # Figure 11a: below S/P = μ/Δ* = 32 /mm the rig's deflection takes the whole stroke.
    inputs = {widget.label: widget for widget in page.select(pn.widgets.TextInput)}
    inputs["Displacement amplitude Δ*"].value = "25um"
    (hatched,) = stuck.fill_renderer.data_source.data["xs"]  # the polygons of the one band
    assert len(hatched) == 1
    x = hatched[0][0]  # its outer boundary
    assert x.min() == 20.0 and 32.0 <= x.max() <= 34.0  # S/P [1/mm], one grid step past 32
    labels = parts["labels"].data_source.data
    assert all(x > 32.0 for x in labels["x"])  # the lines' labels lie where μ_E is defined


def test_a_failure_while_updating_is_a_message_on_the_page(monkeypatch):
    page = explorer_page()
    inputs = {widget.label: widget for widget in page.select(pn.widgets.TextInput)}

    def fails(*args):
        raise OverflowError("math range error")

    monkeypatch.setattr(explorer, "point_values", fails)
    inputs["Contact CoF μ"].value = "0.7"
    shown = " ".join(str(pane.object) for pane in page.select(pn.pane.HTML))
    assert "Cannot show this point (OverflowError: math range error)" in shown

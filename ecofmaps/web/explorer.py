"""A live explorer of the model in the browser (``ecofmaps explore``), built with Panel: one page
per session, the parameters typed with units, the model's numbers and steady loop at that point,
Figure 11's map with the point marked, and the contact CoF behind a typed ECoF. The inputs live
in the page's URL query, so a view is shared as a link."""

from __future__ import annotations

import functools
import html
import math
import warnings

import numpy as np
import panel as pn
from bokeh.models import ColumnDataSource, HoverTool, Legend, LegendItem, Range1d
from bokeh.plotting.contour import contour_data
from matplotlib.colors import to_hex

from ecofmaps._nomenclature import QUANTITIES, RANGES, within
from ecofmaps.correction.inversion import correct_ecof
from ecofmaps.figures.style import ECOF_RATIO_LEVELS, HIGHLIGHT_LEVEL, ecof_ratio_colors
from ecofmaps.maps.grid import compute_map
from ecofmaps.model import NO_GROSS_SLIP
from ecofmaps.model.simulation import fretting_loop
from ecofmaps.model.steady_state import dissipated_energy, energy_cof, slip_amplitude
from ecofmaps.paper import FIGURE_11_STIFFNESS_RATIOS
from ecofmaps.units import DIMENSIONS, DOMAIN, TEXT_LIMIT, bare_number_warning, parse_quantity
from ecofmaps.web import quantity_plot

#: The page's inputs: URL query key -> (quantity of the nomenclature, label, default text);
#: each takes the values of its quantity in the model's domain, :data:`ecofmaps.units.DOMAIN`.
INPUTS = {
    "amplitude": ("amplitude", "Displacement amplitude Δ*", "50um"),
    "load": ("load", "Normal load P", "450N"),
    "stiffness": ("stiffness", "Rig stiffness S", "35MN/m"),
    "mu": ("mu", "Contact CoF μ", "0.8"),
    "aspect_ratio": ("aspect_ratio", "Groove aspect ratio z_o/x_o", "0.2"),
    "ecof": ("ecof", "ECoF μ_E to correct", "0.83"),
    "aspect_ratio_low": ("aspect_ratio", "Scar z_o/x_o from", "0.15"),
    "aspect_ratio_high": ("aspect_ratio", "Scar z_o/x_o to", "0.25"),
}
_MODEL_INPUTS = ("amplitude", "load", "stiffness", "mu", "aspect_ratio")
_MAP_POINTS = (91, 81)  # grid points of the map along S/P and along z_o/x_o
# The map's window, widened to hold the point: S/P [1/m] and the largest z_o/x_o [1]; the
# steps it grows by, so that nearby points share a map; the maps the server keeps in memory.
_MAP_WINDOW = (FIGURE_11_STIFFNESS_RATIOS[0], FIGURE_11_STIFFNESS_RATIOS[-1], 0.4)
_STEPS = np.array([1.0, 2.0, 5.0])
_MAPS_KEPT = 32


def parameter_value(key: str, text: str) -> float:
    """The SI value [m, N, N/m or 1] of input ``key`` of :data:`INPUTS` from its text (``'50um'``,
    ``'inf'``; a bare number is SI); a ValueError naming the input if the text cannot be read, or
    the value is out of range or beyond the model's domain (:data:`ecofmaps.units.DOMAIN`)."""
    name, label, _ = INPUTS[key]
    quantity, (low, high) = QUANTITIES[name], DOMAIN[name]
    text = str(text)
    try:
        value = parse_quantity(text, quantity.kind)
    except ValueError as error:
        raise ValueError(f"{label}: {error}") from None
    if quantity.valid is not None and not bool(within(name, np.asarray(value))):
        rule = RANGES[quantity.valid][1].format(name=quantity.symbol or key)
        raise ValueError(f"{label}: {text!r} is out of range: {rule}")
    if not (low <= value <= high or value == math.inf):  # inf: a rigid rig, in range
        unit = DIMENSIONS[quantity.kind][1]
        raise ValueError(
            f"{label}: {text!r} is beyond the model's domain, {low:g} to {high:g}"
            + ("" if unit == "1" else f" {unit}")
            + (" (or inf, a rigid rig)" if key == "stiffness" else "")
        )
    return value + 0.0  # -0 shown as 0


def bare_number_warnings(texts: dict) -> list[str]:
    """The warnings, naming the input, of ``texts`` (by key of :data:`INPUTS`) implausible in SI."""
    found = []
    for key, text in texts.items():
        if len(str(text)) > TEXT_LIMIT:  # refused as too long: not read as a number here
            continue
        name, label = INPUTS[key][:2]
        warning = bare_number_warning(name, str(text), QUANTITIES[name].kind)
        if warning is not None:
            found.append(f"{label}: {warning}")
    return found


def point_values(amplitude, load, stiffness, mu, aspect_ratio) -> dict:
    """The model's slip amplitude [m], dissipated energy [J], μ_E/μ [1] and steady loop [m, N]
    for one test (parameters in SI, as :func:`ecofmaps.energy_cof`)."""
    point = (amplitude, load, stiffness, mu, aspect_ratio)
    with warnings.catch_warnings(action="ignore"):  # no gross slip: the page says so
        ratio = float(energy_cof(*point)) / mu
    loop = tuple(np.asarray(values) for values in fretting_loop(*point))
    slip, energy = float(slip_amplitude(*point)), float(dissipated_energy(*point))
    return dict(slip_amplitude=slip, dissipated_energy=energy, ecof_ratio=ratio, loop=loop)


def _grown(value: float, upward: bool) -> float:
    """The nearest of 1, 2, 5 times a power of ten beyond ``value`` (up or down)."""
    decade = 10.0 ** math.floor(math.log10(value))
    steps = np.concatenate([_STEPS * decade / 10, _STEPS * decade, _STEPS * decade * 10])
    return float(steps[steps >= value][0] if upward else steps[steps <= value][-1])


def map_window(stiffness_ratio: float, aspect_ratio: float) -> tuple[float, float, float]:
    """The map's window holding a point: S/P from, S/P to [1/m], the largest z_o/x_o [1]:
    Figure 11's, grown in steps of 1, 2, 5 to hold the point (not a rigid rig's), in the domain."""
    low, high, deepest = _MAP_WINDOW
    if math.isfinite(stiffness_ratio):
        low = min(low, _grown(stiffness_ratio * 0.9, upward=False))
        high = max(high, _grown(stiffness_ratio * 1.1, upward=True))
    if aspect_ratio * 1.1 > deepest:
        deepest = _grown(aspect_ratio * 1.1, upward=True)
    (least, most), top = DOMAIN["stiffness_ratio"], DOMAIN["aspect_ratio"][1]
    return float(max(low, least)), float(min(high, most)), float(min(deepest, top))


@functools.lru_cache(maxsize=_MAPS_KEPT)
def _ecof_ratio_map(amplitude: float, mu: float, window: tuple) -> tuple:
    """μ_E/μ over (z_o/x_o, S/P) in the window, and where there is no gross slip (1.0, else 0.0)."""
    low, high, deepest = window
    x, y = np.linspace(low, high, _MAP_POINTS[0]), np.linspace(0.0, deepest, _MAP_POINTS[1])
    dataset = compute_map(x, y, amplitude=amplitude, mu=mu, cache=False)
    stuck = (dataset["regime"] == NO_GROSS_SLIP).astype(np.float64)
    return tuple(np.ascontiguousarray(grid.values.T) for grid in (dataset["ecof_ratio"], stuck))


def _number(value: float, factor: float = 1.0) -> str:
    """``value * factor`` to 3 decimals (6 significant digits from 1e5 up); NaN 'undefined'."""
    if math.isnan(value):
        return "undefined"
    shown = value * factor
    return format(shown, ".3f" if abs(shown) < 1e5 else ".6g")


def _values_html(point: dict, values: dict) -> str:
    """The inputs as read and the model's numbers at the point, each in a span the tests find."""
    read = []
    for key in _MODEL_INPUTS:
        quantity = QUANTITIES[INPUTS[key][0]]
        value = values[key] * quantity.display_factor
        text = "inf (a rigid rig)" if math.isinf(value) else f"{value:g} {quantity.display_unit}"
        read.append(f"{quantity.symbol} = {text.strip()}")
    shown = dict(point, ecof=point["ecof_ratio"] * values["mu"])
    labels = {"slip_amplitude": "Slip amplitude δ*", "dissipated_energy": "Dissipated energy E_d"}
    cells = []
    for key, label in (labels | {"ecof_ratio": "μ_E/μ", "ecof": "μ_E"}).items():
        quantity, value = QUANTITIES[key], shown[key]
        unit = quantity.display_unit if math.isfinite(value) else ""
        cells.append(
            f"<tr><th style='text-align:left;padding-right:1em'>{label}</th>"
            f"<td><span class='ecofmaps-value' data-quantity='{key}' data-unit='{unit}'>"
            f"{_number(value, quantity.display_factor)}</span> {unit}</td></tr>"
        )
    inputs = f"<p style='margin:0 0 6px 0;color:#555'>Read as {', '.join(read)}.</p>"
    gross = math.isfinite(point["ecof_ratio"])
    regime = "" if gross else "<p><b>No gross slip</b> (μP/S ≥ Δ*): μ_E is undefined.</p>"
    return f"{inputs}<table style='font-size:14px'>{''.join(cells)}</table>{regime}"


def _correction_html(values: dict) -> str:
    """The contact CoF behind the typed ECoF, at the point's z_o/x_o and over the interval."""
    rig = {key: values[key] for key in ("amplitude", "load", "stiffness")}
    low, high = values["aspect_ratio_low"], values["aspect_ratio_high"]
    if low > high:
        return "<p>The scar's z_o/x_o interval must run from low to high.</p>"
    try:
        mu = float(correct_ecof(values["ecof"], **rig, aspect_ratio=values["aspect_ratio"]))
        interval = correct_ecof(values["ecof"], **rig, aspect_ratio=(low, high))
    except ValueError as error:
        return f"<p>Cannot correct: {html.escape(str(error))}</p>"
    return (
        f"<p>μ_E = {values['ecof']:g} corrected to the contact CoF: "
        f"μ = <span class='ecofmaps-value' data-quantity='mu_corrected'>{_number(mu)}</span> "
        f"at z_o/x_o = {values['aspect_ratio']:g}; for a scar with z_o/x_o from {low:g} to "
        f"{high:g}, μ from <span class='ecofmaps-value' data-quantity='mu_low'>"
        f"{_number(float(interval.low))}</span> to <span class='ecofmaps-value' "
        f"data-quantity='mu_high'>{_number(float(interval.high))}</span>.</p>"
    )


def _fill_levels(top: float) -> list:
    """The bands' bounds: 1, the levels of Figure 11, and the map's highest μ_E/μ above."""
    return [1.0, *ECOF_RATIO_LEVELS, max(top, ECOF_RATIO_LEVELS[-1]) + 0.01]


def _contour_labels(line_data, scale: tuple) -> dict:
    """Each contour line's level, upright mid its longest piece; ``scale`` [px per unit]."""
    labels = {"x": [], "y": [], "text": [], "angle": []}
    for level, xs, ys in zip(line_data.levels, line_data.xs, line_data.ys, strict=True):
        pieces = np.split(np.arange(len(xs)), np.flatnonzero(np.isnan(xs)))
        piece = max((piece[np.isfinite(xs[piece])] for piece in pieces), key=len)
        if piece.size < 3:
            continue
        before, middle, after = piece[len(piece) // 2 - 1 : len(piece) // 2 + 2]
        angle = math.atan2((ys[after] - ys[before]) * scale[1], (xs[after] - xs[before]) * scale[0])
        labels["x"].append(float(xs[middle]))
        labels["y"].append(float(ys[middle]))
        labels["text"].append(f"{level:.2f}")
        labels["angle"].append((angle + math.pi / 2) % math.pi - math.pi / 2)  # upright text
    return labels


# How the no-gross-slip area is drawn: hatched over a light grey (Bokeh draws no hatch
# over a fill of alpha 0).
_HATCH = dict(line_color="#4d4d4d", fill_color="#d9d9d9", fill_alpha=0.5)
_HATCH |= dict(hatch_pattern="/", hatch_color="#4d4d4d", hatch_scale=10)
#: The part of the map plot (600 × 470) its axes take, roughly. [px]
_MAP_FRAME = (440, 290)


def _map_figure():
    """The μ_E/μ map's figure and, by name, what an update changes in it."""
    title = "μ_E/μ over rig stiffness and groove shape (x_o = Δ*)"
    window = dict(x_range=Range1d(0.0, 1.0), y_range=Range1d(0.0, 1.0), width=600, height=470)
    plot = quantity_plot(title, "stiffness_ratio", "aspect_ratio", **window)
    empty = ([0, 1], [0, 1], np.full((2, 2), np.nan))
    levels = _fill_levels(ECOF_RATIO_LEVELS[-1])
    cmap, norm = ecof_ratio_colors()  # each band in Figure 11's colour of its middle
    middles = (np.asarray(levels[:-1]) + np.asarray(levels[1:])) / 2
    bands = plot.contour(*empty, levels, fill_color=[to_hex(cmap(norm(m))) for m in middles])
    widths = [3.0 if level == HIGHLIGHT_LEVEL else 1.0 for level in ECOF_RATIO_LEVELS]
    lines = plot.contour(*empty, ECOF_RATIO_LEVELS, line_color="black", line_width=widths)
    labels = ColumnDataSource({"x": [], "y": [], "text": [], "angle": []})
    text = dict(text_font_size="11px", text_align="center", text_baseline="middle", padding=1)
    box = dict(background_fill_color="white", background_fill_alpha=0.85)
    plot.text("x", "y", text="text", angle="angle", source=labels, name="labels", **text, **box)
    stuck = plot.contour(*empty, [0.5, 1.5], line_width=1.0, **_HATCH)
    image = ColumnDataSource({"image": [], "x": [], "y": [], "dw": [], "dh": []})
    hover = plot.image(
        "image", x="x", y="y", dw="dw", dh="dh", source=image, palette=["#000000"], global_alpha=0
    )
    marker = ColumnDataSource({"x": [], "y": []})
    circle = {"marker": "circle", "fill_color": "white", "line_color": "black", "line_width": 2}
    point = plot.scatter("x", "y", source=marker, size=13, **circle)
    for renderer, name in ((bands, "bands"), (lines, "lines"), (stuck, "no_gross_slip")):
        renderer.name = name  # found by name by the page's tests
    colorbar = bands.construct_color_bar(width=12, title="μ_E/μ [1]")
    plot.add_layout(colorbar, "right")
    # What the legend shows, by glyphs at no point of the map (a contour's parts have no legend).
    nowhere = [math.nan]
    heavy = plot.line(nowhere, nowhere, line_color="black", line_width=3.0)
    hatched = plot.quad(nowhere, nowhere, nowhere, nowhere, **_HATCH)
    items = [
        LegendItem(label=f"μ_E/μ = {HIGHLIGHT_LEVEL:.2f} (5 % above μ)", renderers=[heavy]),
        LegendItem(label="no gross slip (μP/S ≥ Δ*): μ_E undefined", renderers=[hatched]),
        LegendItem(label="this test", renderers=[point]),
    ]
    style = dict(orientation="horizontal", label_text_font_size="11px", spacing=12, margin=4)
    plot.add_layout(Legend(items=items, **style), "below")
    tips = [("S/P", "$x{0.0} 1/mm"), ("z_o/x_o", "$y{0.000}"), ("μ_E/μ", "@image{0.000}")]
    plot.add_tools(HoverTool(tooltips=tips, renderers=[hover]))
    parts = dict(x_range=plot.x_range, y_range=plot.y_range, bands=bands, colorbar=colorbar)
    return plot, parts | dict(lines=lines, labels=labels, stuck=stuck, image=image, marker=marker)


def _show_map(values: dict, parts: dict) -> None:
    ratio = values["stiffness"] / values["load"]
    window = map_window(ratio, values["aspect_ratio"])
    grid, stuck = _ecof_ratio_map(values["amplitude"], values["mu"], window)
    x = np.linspace(window[0], window[1], _MAP_POINTS[0]) * 1e-3  # 1/mm
    y = np.linspace(0.0, window[2], _MAP_POINTS[1])
    for axis, (start, end) in (("x_range", (x[0], x[-1])), ("y_range", (y[0], y[-1]))):
        parts[axis].update(start=start, end=end, reset_start=start, reset_end=end)
    finite = grid[np.isfinite(grid)]
    levels = _fill_levels(float(finite.max()) if finite.size else 1.0)
    parts["bands"].set_data(contour_data(x, y, grid, levels, want_line=False))
    parts["bands"].levels = parts["colorbar"].levels = levels
    parts["colorbar"].ticker.ticks = levels[:-1]
    drawn = contour_data(x, y, grid, ECOF_RATIO_LEVELS, want_fill=False)
    parts["lines"].set_data(drawn)
    scale = (_MAP_FRAME[0] / (x[-1] - x[0]), _MAP_FRAME[1] / (y[-1] - y[0]))
    parts["labels"].data = _contour_labels(drawn.line_data, scale)
    parts["stuck"].set_data(contour_data(x, y, stuck, [0.5, 1.5]))
    parts["image"].data = dict(image=[grid], x=[x[0]], y=[0.0], dw=[x[-1] - x[0]], dh=[y[-1]])
    shown = int(math.isfinite(ratio))  # a rigid rig's point is not drawn
    parts["marker"].data = {"x": [ratio * 1e-3][:shown], "y": [values["aspect_ratio"]][:shown]}


def explorer_page():
    """The explorer's page for one browser session (a Panel layout)."""
    # The query as typed: Panel's own reading of it turns '0.8' into a float, which a text
    # input refuses, so the inputs start from the request's text and the sync only writes it.
    query = {
        key: values[-1][: TEXT_LIMIT + 1].decode("utf-8", "replace")
        for key, values in (pn.state.session_args or {}).items()
        if key in INPUTS and values and isinstance(values[-1], bytes)
    }
    inputs = {}
    for key, (_, label, default) in INPUTS.items():
        width = 220 if key in _MODEL_INPUTS else 160
        inputs[key] = pn.widgets.TextInput(label=label, value=query.get(key, default), width=width)
    if pn.state.location is not None:
        for key, widget in inputs.items():
            pn.state.location.sync(widget, {"value": key})
    values_pane = pn.pane.HTML("", width=260)
    correction_pane = pn.pane.HTML("", width=760, margin=(18, 10))
    message = pn.pane.HTML("", width=900, styles={"color": "#b00020"})
    notice = pn.pane.HTML("", width=900, styles={"color": "#8a4b00"})
    loop_source = ColumnDataSource({"x": [], "y": []})
    loop = quantity_plot("Steady fretting loop", "displacement", "force", width=440, height=380)
    loop.line("x", "y", source=loop_source, line_width=2, color="#1f77b4")
    map_plot, map_parts = _map_figure()

    def update(*_events):
        """Show the inputs' point; any failure is a message on the page, never Panel's."""
        texts = {key: widget.value for key, widget in inputs.items()}
        notice.object = "".join(
            f"<p style='margin:2px 0'>{html.escape(warning)}</p>"
            for warning in bare_number_warnings(texts)
        )
        try:
            values = {key: parameter_value(key, widget.value) for key, widget in inputs.items()}
        except ValueError as error:
            message.object = f"<p style='margin:2px 0'>{html.escape(str(error))}</p>"
            return
        try:
            point = point_values(*(values[key] for key in _MODEL_INPUTS))
            values_pane.object = _values_html(point, values)
            loop_source.data = {"x": point["loop"][0] * 1e6, "y": point["loop"][1]}
            _show_map(values, map_parts)
            correction_pane.object = _correction_html(values)
        except Exception as error:  # a page must stay up whatever the model says
            text = f"Cannot show this point ({type(error).__name__}: {error})"
            message.object = f"<p style='margin:2px 0'>{html.escape(text)}</p>"
            return
        message.object = ""

    for widget in inputs.values():
        widget.param.watch(update, "value")
    update()
    heading = pn.pane.HTML("<h3 style='margin:8px 0 0 0'>At this point</h3>")
    at_point = pn.Column(*(inputs[key] for key in _MODEL_INPUTS), heading, values_pane)
    intro = pn.pane.HTML(
        "<h2 style='margin:4px 0'>ecofmaps explorer: the compliant wear-scar model</h2>"
        "<p style='margin:0'>Type quantities with units (50um, 35MN/m; a bare number is SI). "
        "The URL keeps the inputs: copy it to share this view.</p>",
        width=1100,
    )
    plots = pn.Row(at_point, pn.pane.Bokeh(loop), pn.pane.Bokeh(map_plot))
    correcting = pn.pane.HTML("<h3 style='margin:0'>Correct a reported ECoF</h3>")
    correction = [inputs[key] for key in ("ecof", "aspect_ratio_low", "aspect_ratio_high")]
    correction = pn.Row(*correction, correction_pane)
    return pn.Column(intro, message, notice, plots, correcting, correction)


def warm_up() -> None:
    """Compile the model and fill the default point's map, so the first page comes at once."""
    values = {key: parameter_value(key, default) for key, (_, _, default) in INPUTS.items()}
    point_values(*(values[key] for key in _MODEL_INPUTS))
    window = map_window(values["stiffness"] / values["load"], values["aspect_ratio"])
    _ecof_ratio_map(values["amplitude"], values["mu"], window)
    _correction_html(values)

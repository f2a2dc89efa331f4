"""A fretting test's results as one HTML page that opens offline (``ecofmaps loops --report``):
Bokeh's, its JavaScript and CSS inline. The coefficients of friction over the cycles with the
quality flags, the lab's numbers (docs/lab.md), measured loops beside the model's, the table of
``ecofmaps loops`` and the inputs, version and date."""

from __future__ import annotations

import datetime
import html
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import xarray as xr
from bokeh.core.templates import CSS_RESOURCES, JS_RESOURCES, get_env
from bokeh.embed import file_html
from bokeh.layouts import column, row
from bokeh.models import (
    BasicTickFormatter,
    ColumnDataSource,
    CustomJS,
    DataTable,
    Div,
    HoverTool,
    HTMLTemplateFormatter,
    MultiChoice,
    StringFormatter,
    TableColumn,
)
from bokeh.palettes import Category10_10
from bokeh.plotting import figure
from bokeh.resources import INLINE

from ecofmaps._nomenclature import QUANTITIES, axis_label, transition_texts, with_se
from ecofmaps._version import __version__
from ecofmaps.io.files import atomic_path
from ecofmaps.io.tables import results_table
from ecofmaps.lab import transition
from ecofmaps.lab.regime import sliding_condition_line
from ecofmaps.lab.wear import cumulated_energy
from ecofmaps.measured.quality import REASONS, has_reason, quality_summary
from ecofmaps.model.simulation import fretting_loop
from ecofmaps.web import quantity_plot

#: Cycles whose loops a report carries by default, spread evenly over the test, for the reader
#: to pick from: the bulk of a short test's report.
LOOPS_CARRIED = 60
_MODEL_POINTS = 40  # points on each slip branch of a model loop
_MODEL_BATCH = 64  # model loops are computed in batches of a multiple of this many
# The plots over the cycles: width of their frames, and the room left of them for the axis
# labels, the same in both so that their cycle axes line up; the page's width. [px]
_FRAME = (560, 130)
_WIDTH = 1240
_NEEDED = ("cycle", "ecof", "gicof", "quality", "regime", "load")
# The table: the CSV's significant digits, a number cell (empty for NaN, as in the CSV), the
# width of a character and the room around it, the table's width (fits a 1400 px window) and
# the room for its scroll bar. [px]
_DIGITS = 6
_NUMBER_CELL = (
    '<div style="text-align: right"><%= (value == null || value !== value) ? "" : '
    "value.toFixed(DECIMALS) %></div>"
)
_CHARACTER, _CELL_ROOM = 6.5, 10
_TABLE_WIDTH, _TABLE_ROOM = 1350, 20

# Shows the measured loops of the cycles picked and their model's, each pair in one colour.
_PICK_LOOPS = """
const all = carried.data;
const at = choice.value.map((name) => all.label.indexOf(name));
const color = at.map((_, k) => palette[k % palette.length]);
const label = choice.value.slice();
measured.data = {xs: at.map((i) => all.xs[i]), ys: at.map((i) => all.ys[i]), label, color};
const kept = at.map((_, k) => k).filter((k) => all.model_xs[at[k]].length > 0);
model.data = {xs: kept.map((k) => all.model_xs[at[k]]), ys: kept.map((k) => all.model_ys[at[k]]),
              color: kept.map((k) => color[k])};
"""


def write_report(path, results: xr.Dataset, *, loops=None, inputs=None, lab=None) -> Path:
    """``path``, written atomically: the results of :func:`ecofmaps.analyze_loops` as an offline
    HTML page carrying the loops of cycles ``loops`` (default :data:`LOOPS_CARRIED` spread
    evenly), and the rows ``inputs`` (what the results came from) and ``lab`` as given."""
    document = report_document(results, loops=loops, inputs=inputs, lab=lab)
    title = "ecofmaps report" + (f": {inputs['files']}" if inputs and "files" in inputs else "")
    # Bokeh's own JavaScript and CSS, written in. Not file_html(..., INLINE): that also asks
    # the page to fetch the external files of every model class imported in this process
    # (Panel's, once Panel is imported), which a page opened offline cannot.
    own = INLINE.clone(components=["bokeh", "bokeh-widgets", "bokeh-tables"])
    page = get_env().from_string(
        '{% extends "file.html.jinja" %}{% block css_resources %}{{ own_css }}{% endblock %}'
        "{% block js_resources %}{{ own_js }}{% endblock %}"
    )
    own_js = JS_RESOURCES.render(js_files=[], js_raw=own.js_raw, hashes={})
    own_css = CSS_RESOURCES.render(css_files=[], css_raw=own.css_raw)
    resources = dict(own_js=own_js, own_css=own_css)
    text = file_html(document, None, title=title, template=page, template_variables=resources)
    with atomic_path(path) as temporary:
        Path(temporary).write_text(text, encoding="utf-8")
    return Path(path)


def recording_inputs(recording, load: float, *, flip_force: bool = False) -> dict[str, str]:
    """The ``inputs`` of :func:`write_report`: file, ``load`` [N], each column read and its unit."""
    read = []
    for name, column_name in recording.columns.items():
        unit = recording.units.get(name, "1")
        read.append(f"{name}: {column_name!r}" + ("" if unit == "1" else f" in {unit}"))
    inputs = {"files": str(recording.path), "load": f"{load:g} N"}
    inputs["columns and units assumed"] = "; ".join(read)
    if flip_force:
        inputs["force sign"] = "read with the other sign (--flip-force)"
    return inputs


def report_document(results: xr.Dataset, *, loops=None, inputs=None, lab=None):
    """The Bokeh layout of :func:`write_report`'s page (same parameters)."""
    missing = [name for name in _NEEDED if name not in results.variables]
    if missing:
        raise ValueError(
            f"results lack {', '.join(missing)}: give the Dataset of ecofmaps.analyze_loops"
        )
    cycle, quality = results["cycle"].values, results["quality"].values
    flagged = {reason: cycle[has_reason(quality, reason)] for reason in REASONS}
    flagged = {reason: cycles for reason, cycles in flagged.items() if cycles.size}  # in order
    evolution, flags = _evolution_figures(results, flagged)
    parts = [
        _header(results, inputs or {}),
        _lab_numbers(results, lab or {}),
        row(column(evolution, flags), _quality_counts(results, flagged)),
    ]
    if "loop_displacement" in results.variables:
        parts.append(_loops_panel(results, _carried_cycles(results, loops)))
    elif loops is not None:
        raise ValueError("loops needs the loops: call analyze_loops(..., keep_loops=True)")
    else:
        parts.append(Div(text="<p>The loops were not kept (keep_loops=False).</p>"))
    parts.append(_table(results))
    return column(*parts, styles={"font-family": "sans-serif", "margin": "0 12px"})


def _rows_table(rows: Mapping, css_class: str) -> str:
    """An HTML table of ``rows``, a name and its value on each row."""
    cells = "".join(
        f"<tr><th style='text-align:left;padding-right:1em'>{html.escape(str(key))}</th>"
        f"<td>{html.escape(str(value))}</td></tr>"
        for key, value in rows.items()
    )
    return f"<table class='{css_class}' style='font-size:14px'>{cells}</table>"


def _header(results: xr.Dataset, inputs: Mapping) -> Div:
    """The title, the inputs, the version and date, and the quality's summary."""
    written = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    rows = dict(inputs) | {"ecofmaps version": __version__, "written": written}
    rows["cycles"] = quality_summary(results["quality"].values)
    rows["sliding condition"] = sliding_condition_line(results)
    return Div(
        text="<h1 style='margin:8px 0 4px 0;font-size:22px'>Fretting test: friction cycle by "
        "cycle</h1><p style='margin:0 0 6px 0;max-width:1100px'>ECoF μ_E = E_d/(4Pδ*) "
        "(eq. 1), GICoF = Q/P at the centre of the slip, where the loop crosses Q = SΔ "
        "(eq. 17-18; a fit over its central 70 %), and μ read along the stroke, from "
        "<code>ecofmaps.analyze_loops</code>. Values that cannot be stood behind are left "
        "out, and the quality flags say why.</p>" + _rows_table(rows, "ecofmaps-inputs"),
        width=_WIDTH,
    )


def _lab_numbers(results: xr.Dataset, lab: Mapping) -> Div:
    """The test's cumulated dissipated energy, its transition if it crosses one, and ``lab``."""
    name, last = QUANTITIES["cumulated_energy"].long_name, float(results["cycle"][-1])
    try:
        energy = with_se("cumulated_energy", *cumulated_energy(results))
        rows = {name: f"{energy} over cycles 1 to {last:.0f}"}
    except ValueError as error:
        rows = {name: str(error)}
    try:
        found = transition(results)
    except ValueError as error:
        rows["transition to gross slip"] = f"none: {error}"
    else:
        rows |= {QUANTITIES[q].long_name: text for q, text in transition_texts(found)}
    rows |= lab
    return Div(
        text="<h3 style='margin:8px 0 4px 0'>The lab's numbers (<code>ecofmaps.transition"
        "</code>, <code>ecofmaps.energy_wear</code>, <code>ecofmaps.loop_scar_closure</code>: "
        "with a scar profile, <code>ecofmaps loops --scar-profile</code> or <code>ecofmaps wear"
        "</code>)</h3>" + _rows_table(rows, "ecofmaps-lab"),
        width=_WIDTH,
    )


def _evolution_figures(results: xr.Dataset, flagged: dict):
    """The coefficients of friction against the cycle, and the cycles each flag marks."""
    cycle = results["cycle"].values
    data = {"cycle": cycle, "quality": results["quality"].values.astype(str)}
    for name in ("ecof", "gicof", "mu_resolved", "mu_resolved_se"):
        data[name] = results[name].values if name in results else np.full(cycle.size, np.nan)
    data["mu_low"] = data["mu_resolved"] - 2.0 * data["mu_resolved_se"]
    data["mu_high"] = data["mu_resolved"] + 2.0 * data["mu_resolved_se"]
    source = ColumnDataSource(data)
    plot = _cycle_figure("Coefficients of friction over the test", 300)
    plot.yaxis.axis_label = "Coefficient of friction [1]"
    if "mu_resolved" in results:
        band = {"color": "#2ca02c", "alpha": 0.25, "legend_label": "μ ± 2 se"}
        plot.varea("cycle", "mu_low", "mu_high", source=source, **band)
    lines = {  # μ on top: the most precise of the three
        "ecof": ("#ff7f0e", "ECoF μ_E"),
        "gicof": ("#1f77b4", "GICoF (Q/P on Q = SΔ)"),
        "mu_resolved": ("#2ca02c", "μ read along the stroke"),
    }
    drawn = {}
    for name, (color, legend) in lines.items():
        look = dict(source=source, color=color)
        if name in results:
            drawn[name] = plot.line("cycle", name, line_width=1.5, legend_label=legend, **look)
        if cycle.size <= 400 and name != "mu_resolved":
            plot.scatter("cycle", name, size=3, **look)
    tips = [("cycle", "@cycle"), ("ECoF", "@ecof{0.000000}"), ("GICoF", "@gicof{0.000000}")]
    tips += [("μ", "@mu_resolved{0.000000}"), ("quality", "@quality")]
    plot.add_tools(HoverTool(tooltips=tips, mode="vline", renderers=[drawn["ecof"]]))
    plot.legend.click_policy = "hide"
    plot.add_layout(plot.legend[0], "right")  # beside the plot: the curves stay uncovered
    return plot, _flags_figure(flagged, plot)


def _cycle_figure(title: str, height: int, tools="pan,box_zoom,wheel_zoom,reset,save", **options):
    """A plot over the cycles, ``height`` [px] high, its frame lined up with the other's."""
    frame = dict(frame_width=_FRAME[0], frame_height=height, min_border_left=_FRAME[1])
    labels = dict(title=title, x_axis_label=axis_label("cycle", plain=True))
    plot = figure(tools=tools, **labels, **frame, **options)
    plot.xaxis.formatter = BasicTickFormatter(use_scientific=False)
    return plot


def _flags_figure(flagged: dict, evolution):
    """A strip below the coefficients: a mark at each cycle a quality reason flags."""
    if not flagged:
        return Div(text="<p>No cycle is flagged: every cycle's quality is 'ok'.</p>")
    reasons = list(flagged)[::-1]  # the first reason at the top
    ranges = dict(x_range=evolution.x_range, y_range=reasons, toolbar_location=None)
    title = "Quality flags (the values they leave out are NaN)"
    plot = _cycle_figure(title, 26 * len(reasons), tools="xpan,xwheel_zoom,reset", **ranges)
    reason = [reason for reason, cycles in flagged.items() for _ in cycles]
    marks = ColumnDataSource({"cycle": np.concatenate(list(flagged.values())), "reason": reason})
    mark = {"marker": "dash", "size": 10, "line_width": 2, "color": "#d62728"}
    plot.scatter("cycle", "reason", source=marks, angle=np.pi / 2, **mark)
    plot.add_tools(HoverTool(tooltips=[("cycle", "@cycle"), ("flag", "@reason")]))
    return plot


def _quality_counts(results: xr.Dataset, flagged: dict) -> Div:
    """The number of cycles each quality reason flags, with what it means."""
    ok = int(np.sum(results["quality"].values.astype(str) == "ok"))
    rows = [("ok", ok, "every value of the cycle stands")]
    rows += [(reason, cycles.size, REASONS[reason][0]) for reason, cycles in flagged.items()]
    cells = "".join(
        f"<tr style='vertical-align:top'><td><code>{html.escape(name)}</code></td>"
        f"<td style='text-align:right;padding:0 8px'>{count}</td>"
        f"<td>{html.escape(meaning)}</td></tr>"
        for name, count, meaning in rows
    )
    return Div(
        text=f"<h3 style='margin:4px 0'>Quality of the {results['cycle'].size} cycles</h3>"
        "<table class='ecofmaps-quality' style='font-size:13px;border-collapse:collapse'>"
        "<tr><th style='text-align:left'>flag</th><th style='padding:0 8px'>cycles</th>"
        f"<th style='text-align:left'>what it means</th></tr>{cells}</table>",
        width=_WIDTH - 880,
    )


def _carried_cycles(results: xr.Dataset, loops) -> np.ndarray:
    labels = results["cycle"].values
    if loops is None:
        count = min(LOOPS_CARRIED, labels.size)
        return labels[np.unique(np.round(np.linspace(0, labels.size - 1, count)).astype(int))]
    chosen = np.asarray(list(loops)).astype(labels.dtype)
    unknown = chosen[~np.isin(chosen, labels)]
    if unknown.size:
        raise ValueError(
            f"loops names cycle {unknown[0]}, which the results do not hold "
            f"(cycles {labels[0]} to {labels[-1]})"
        )
    return chosen


def _model_loops(results: xr.Dataset) -> tuple[list, list]:
    """The model's steady loop of each cycle for its μ and z_o/x_o read along the stroke [µm, N]."""
    xs, ys = [np.zeros(0)] * results["cycle"].size, [np.zeros(0)] * results["cycle"].size
    if "mu_resolved" not in results or "aspect_ratio" not in results:
        return xs, ys
    names = ("amplitude", "stiffness", "mu_resolved", "aspect_ratio")
    amplitude, stiffness, mu, ratio = values = [results[name].values for name in names]
    usable = np.isfinite(values).all(axis=0) & (ratio >= 0)
    usable &= (amplitude > 0) & (stiffness > 0) & (mu > 0)
    if not usable.any():
        return xs, ys
    # Padded to a multiple of _MODEL_BATCH loops (repeating them): the compiled model is then
    # reused by every report, not compiled again for each number of loops.
    size = -(-int(usable.sum()) // _MODEL_BATCH) * _MODEL_BATCH
    amplitude, stiffness, mu, ratio = (np.resize(v[usable], size) for v in values)
    loop = fretting_loop(amplitude, float(results["load"]), stiffness, mu, ratio, num=_MODEL_POINTS)
    displacement, force = np.round(np.asarray(loop[0]) * 1e6, 4), np.round(np.asarray(loop[1]), 3)
    for row_index, index in enumerate(np.flatnonzero(usable)):
        xs[index], ys[index] = displacement[row_index], force[row_index]
    return xs, ys


def _loops_panel(results: xr.Dataset, carried: np.ndarray):
    """The measured loops of the picked cycles with their model loops, and the picker."""
    chosen = results.sel(cycle=carried)
    names = [f"cycle {label}" for label in carried]
    model_xs, model_ys = _model_loops(chosen)
    measured_x = np.round(chosen["loop_displacement"].values * 1e6, 4)
    measured_y = np.round(chosen["loop_force"].values, 3)
    kept = np.isfinite(measured_x) & np.isfinite(measured_y)
    xs = [x[keep] for x, keep in zip(measured_x, kept, strict=True)]
    ys = [y[keep] for y, keep in zip(measured_y, kept, strict=True)]
    loops = dict(label=names, xs=xs, ys=ys, model_xs=model_xs, model_ys=model_ys)
    all_loops = ColumnDataSource(loops)
    first = list(dict.fromkeys([names[0], names[len(names) // 2], names[-1]]))
    palette = list(Category10_10)
    # The loops first shown, as _PICK_LOOPS shows those picked (at most three: a colour each)
    at = [names.index(name) for name in first]
    colors = palette[: len(first)]
    shown = {"xs": [xs[i] for i in at], "ys": [ys[i] for i in at], "label": first, "color": colors}
    measured = ColumnDataSource(shown, name="shown-loops")
    kept = [k for k, i in enumerate(at) if len(model_xs[i])]
    model = {"xs": [model_xs[at[k]] for k in kept], "ys": [model_ys[at[k]] for k in kept]}
    model = ColumnDataSource(model | {"color": [colors[k] for k in kept]}, name="shown-models")
    title = "Measured loops (lines) and the model's (dashed)"
    plot = quantity_plot(title, "displacement", "force", width=700, height=460)
    plot.multi_line(
        "xs", "ys", source=measured, color="color", line_width=1.6, legend_field="label"
    )
    plot.multi_line("xs", "ys", source=model, color="color", line_width=1.4, line_dash="dashed")
    plot.legend.location = "top_left"
    title = f"Cycles shown (pick others; the page carries the loops of {len(names)} cycles "
    title += "spread over the test)"
    choice = MultiChoice(title=title, value=first, options=names, width=480, name="loop-picker")
    picked = dict(carried=all_loops, choice=choice, measured=measured, model=model, palette=palette)
    choice.js_on_change("value", CustomJS(args=picked, code=_PICK_LOOPS))
    note = Div(
        text="<p>Each loop is centred (the sensors' offsets removed). The dashed loop is the "
        "model's steady loop (eq. 9, 10, 16) for the cycle's amplitude, rig stiffness S, "
        "and the friction μ and groove z_o/x_o read along the stroke; a cycle without "
        "that reading has none.</p>",
        width=480,
    )
    return row(plot, column(choice, note))


def _column_decimals(values) -> int:
    """The decimals that show the largest of ``values`` with :data:`_DIGITS` significant digits."""
    values = np.abs(np.asarray(values, dtype=np.float64))
    values = values[np.isfinite(values) & (values > 0)]
    return int(max(0, _DIGITS - 1 - np.floor(np.log10(values.max())))) if values.size else 0


def _table(results: xr.Dataset):
    """The table of ``ecofmaps loops --out``, 6 significant digits, the first column frozen."""
    table = results_table(results)
    data, columns = {}, []
    for name in table.columns:
        values = table[name].to_numpy()
        if values.dtype.kind == "f":
            values = np.array([float(f"{value:.{_DIGITS}g}") for value in values])
            decimals = str(_column_decimals(values))
            formatter = HTMLTemplateFormatter(template=_NUMBER_CELL.replace("DECIMALS", decimals))
            longest = len(name)
        else:
            formatter = StringFormatter()
            longest = max([len(name), *(len(str(value)) for value in values)])
        # The name shows, and the values (a quality with many flags scrolls within its cell)
        width = min(200, max(56, round(_CHARACTER * longest + _CELL_ROOM)))
        columns.append(TableColumn(field=name, title=name, formatter=formatter, width=width))
        data[name] = values
    # The last column (the quality) as wide as the table leaves it, but never narrower than 90
    others = sum(column.width for column in columns[:-1])
    columns[-1].width = min(columns[-1].width, max(90, _TABLE_WIDTH - _TABLE_ROOM - others))
    heading = Div(
        text="<h3 style='margin:12px 0 4px 0'>The table (as <code>ecofmaps loops --out</code> "
        "writes it; click a column's name to sort)</h3>",
        width=_WIDTH,
    )
    layout = dict(width=_TABLE_WIDTH, height=380, autosize_mode="none", frozen_columns=1)
    options = dict(index_position=None, sortable=True, css_classes=["ecofmaps-table"], **layout)
    return column(heading, DataTable(source=ColumnDataSource(data), columns=columns, **options))

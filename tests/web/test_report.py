"""The HTML report of a test (ecofmaps.web.report): what it holds, its size, and the page in a
real browser, opened from file:// with nothing fetched."""

import contextlib
import csv
import html
import io
import re
import warnings

import numpy as np
import pytest
from bokeh.models import Div

import ecofmaps
from ecofmaps import cli
from ecofmaps.cli import loops
from ecofmaps.io.tables import results_csv
from ecofmaps.measured.quality import REASONS, LoopQualityWarning
from ecofmaps.paper import EXAMPLE_2
from ecofmaps.web import report
from ecofmaps.web.report import LOOPS_CARRIED, report_document, write_report
from tests.cli.commands import run
from tests.web.pages import CANVAS_INK, console_errors, deep_texts, wait_for

INPUTS = {"files": "test.csv", "load": "450 N", "units assumed": "displacement um, force N"}


def damaged_recording():
    """40 cycles of a deepening groove, one of them damaged (its force turned over). [m], [N]"""
    displacement, force = ecofmaps.synthetic_recording(
        **dict(EXAMPLE_2, aspect_ratio=np.linspace(0.02, 0.2, 40)), samples_per_cycle=160,
        force_noise=4.0, displacement_noise=2.5e-7, seed=3,
    )  # fmt: skip
    force[160 * 5 : 160 * 5 + 80] *= -1.0
    return displacement, force


@pytest.fixture(scope="module")
def results():
    """The analysis of :func:`damaged_recording`."""
    with pytest.warns(LoopQualityWarning):
        return ecofmaps.analyze_loops(*damaged_recording(), 450.0, resolve=True, keep_loops=True)


@pytest.fixture(scope="module")
def command(tmp_path_factory):
    """``ecofmaps loops test.csv --load 450N --out t.csv --report r.html`` on the recording of
    :func:`damaged_recording`: the paths of the table and of the page, and what it printed."""
    folder = tmp_path_factory.mktemp("loops")
    displacement, force = damaged_recording()
    lines = [f"{x * 1e6:.17g},{q:.17g}" for x, q in zip(displacement, force, strict=True)]
    (folder / "test.csv").write_text("displacement,force\n" + "\n".join(lines) + "\n")
    table, page = folder / "t.csv", folder / "r.html"
    printed, errors = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(printed), contextlib.redirect_stderr(errors):
        status = cli.main(
            ["loops", str(folder / "test.csv"), "--load", "450N", "--out", str(table),
             "--report", str(page)]
        )  # fmt: skip
    assert status == 0, errors.getvalue()
    return table, page, printed.getvalue()


@pytest.fixture(scope="module")
def page(command):
    """The page the command wrote."""
    return command[1]


def test_a_column_shows_its_largest_value_to_six_significant_digits():
    columns = ([0.80003, 0.806507], [50.1348, 9.5], [], [np.nan, 0.0])
    assert [report._column_decimals(values) for values in columns] == [6, 4, 0, 0]


def test_the_page_fetches_nothing(page):
    text = page.read_text(encoding="utf-8")
    assert not re.search(r"<script[^>]*\bsrc=", text)
    assert not re.search(r"<link[^>]*\bhref=", text)
    assert "Bokeh" in text  # the library is in the page, inline


def test_the_page_fetches_nothing_once_panel_is_imported(results, tmp_path):
    """Panel's models ask every Bokeh page made in the process to fetch files of theirs."""
    import panel  # noqa: F401  (the explorer imports it)

    text = write_report(tmp_path / "r.html", results).read_text(encoding="utf-8")
    assert not re.search(r"<script[^>]*\bsrc=", text)
    assert not re.search(r"<link[^>]*\bhref=", text)


def test_the_page_gives_the_inputs_version_and_flag_meanings(results):
    text = _texts(report_document(results, inputs=INPUTS))
    for label, value in INPUTS.items():
        assert f"{label}</th><td>{value}<" in text
    assert ecofmaps.__version__ in text
    condition = results.attrs["sliding_condition"]
    assert condition == "gross slip"  # the damaged cycle refused, every other slides
    assert f"sliding condition</th><td>{condition}<" in text
    flagged = {r for q in results.quality.values for r in str(q).split("+")} - {"ok"}
    assert flagged  # the damaged cycle
    quality = results.quality.values
    for reason in flagged:
        count = sum(reason in str(q).split("+") for q in quality)
        assert (
            f"<code>{reason}</code></td><td style='text-align:right;padding:0 8px'>{count}<" in text
        )
        assert REASONS[reason][0] in text


def _texts(document) -> str:
    return html.unescape("".join(div.text for div in document.select({"type": Div})))


def test_a_sweep_across_the_transition_shows_it():
    """A Mindlin sphere swept from 0.45 to 1.8 Δ_t on a rig whose stiffness was given."""
    from tests import mindlin
    from tests.lab_cases import DELTA_T, LOAD, MU

    stiffness = 35e6
    at = mindlin.transition_amplitude(MU, LOAD, DELTA_T, stiffness)
    applied = mindlin.sweep(np.repeat(np.linspace(0.45, 1.8, 20) * at, 2))
    _, force = mindlin.drive(mindlin.Contact(MU, LOAD, DELTA_T), applied, stiffness)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sweep = ecofmaps.analyze_loops(applied, force, LOAD, rig_stiffness=stiffness)
    text = _texts(report_document(sweep))
    number = r"(\d+\.\d+) ± \d\.?\d*"
    shown = {
        "Δ_t": (at * 1e6, rf"transition displacement amplitude Δ_t</th><td>{number} µm<"),
        "δ_t": (DELTA_T * 1e6, rf"contact's transition amplitude δ_t</th><td>{number} µm<"),
        "μ_t": (MU, rf"at the transition μ_t = Q\*/P</th><td>{number}<"),
    }
    for symbol, (truth, pattern) in shown.items():
        assert float(re.search(pattern, text)[1]) == pytest.approx(truth, rel=0.05), symbol
    assert "cumulated dissipated energy ΣE_d</th><td>" in text and "mixed slip" in text
    unknown = "transition amplitude δ_t</th><td>needs --rig-stiffness (the rig's own; without it"
    bare = sweep.drop_attrs(deep=False)  # the sphere's spring stands for the rig's, or none
    assert unknown not in _texts(report_document(bare))
    bare["quality"] = bare.quality.where(bare.quality != "mindlin-stick", "ok")
    assert unknown in _texts(report_document(bare))


def test_a_constant_amplitude_says_there_is_no_transition(results):
    text = _texts(report_document(results))
    assert "transition to gross slip</th><td>none: results never cross the transition" in text
    energy = re.search(r"ΣE_d</th><td>(\d\.\d+) ± [\d.e-]+ J over cycles 1 to 40<", text)
    cycle, energy_per_cycle = results.cycle.values, results.dissipated_energy.values
    kept = np.isfinite(energy_per_cycle)  # the damaged cycle's refused: read between its two
    total = np.interp(cycle, cycle[kept], energy_per_cycle[kept]).sum()
    assert float(energy[1]) == pytest.approx(total, rel=1e-3)


def test_the_page_carries_some_loops_and_the_model(results):
    document = report_document(results, loops=[1, 7, 40])
    picker = document.select_one({"name": "loop-picker"})
    assert picker.options == ["cycle 1", "cycle 7", "cycle 40"]
    assert picker.value == ["cycle 1", "cycle 7", "cycle 40"]
    models = document.select_one({"name": "shown-models"})
    assert len(models.data["xs"]) == 3  # every cycle here has μ and z_o/x_o read
    default = report_document(results).select_one({"name": "loop-picker"})
    assert len(default.options) == min(LOOPS_CARRIED, results.cycle.size)
    assert default.value == ["cycle 1", "cycle 21", "cycle 40"]


def test_bad_arguments_say_what_is_wrong(results, tmp_path):
    with pytest.raises(ValueError, match="loops names cycle 99"):
        write_report(tmp_path / "r.html", results, loops=[1, 99])
    with pytest.raises(ValueError, match="keep_loops=True"):
        write_report(tmp_path / "r.html", results.drop_vars(["loop_displacement", "loop_force"]),
                     loops=[1])  # fmt: skip
    with pytest.raises(ValueError, match="results lack quality"):
        write_report(tmp_path / "r.html", results.drop_vars("quality"))
    with pytest.raises(OSError):
        write_report(tmp_path / "no-such-folder" / "r.html", results)
    assert list(tmp_path.iterdir()) == []  # nothing half written


def test_ten_thousand_cycles_stay_under_5_MB(results, tmp_path):
    """A 1e4-cycle test (the 40 cycles repeated): the table is all there, the loops a subset."""
    cycles = 10_000
    long = results.isel(cycle=np.arange(cycles) % results.cycle.size)
    long = long.assign_coords(cycle=np.arange(1, cycles + 1))
    page = write_report(tmp_path / "long.html", long, inputs=INPUTS)
    assert page.stat().st_size < 5e6, page.stat().st_size


def test_the_command_reports_the_analysis_it_tabled(command, monkeypatch, tmp_path):
    """--report draws the results whose table --out wrote: one analysis, not a second one."""
    table, page, printed = command
    assert f"the report in {page}" in printed
    drawn = []
    monkeypatch.setattr(report, "write_report", lambda path, results, **_: drawn.append(results))
    recording = table.parent / "test.csv"
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        status = cli.main(
            ["loops", str(recording), "--load", "450N", "--out", str(tmp_path / "t.csv"),
             "--report", str(tmp_path / "r.html")]
        )  # fmt: skip
    assert status == 0 and len(drawn) == 1
    assert results_csv(drawn[0]) == (tmp_path / "t.csv").read_text() == table.read_text()
    assert "loop_displacement" in drawn[0]  # the loops were kept for the page


def test_report_errors_are_one_line(command, tmp_path, monkeypatch, capsys):
    recording = command[0].parent / "test.csv"
    status, _, err = run(capsys, "loops", recording, recording, "--load", "450N", "--report",
                         tmp_path / "r.html")  # fmt: skip
    assert status == 2 and "--report writes the page of one recording" in err
    status, _, err = run(capsys, "loops", recording, "--load", "450N", "--report",
                         tmp_path / "no-such-folder" / "r.html")  # fmt: skip
    assert status == 2 and "its directory does not exist" in err
    status, _, err = run(capsys, "loops", recording, "--load", "450N", "--report", recording)
    assert status == 2 and "would write over the input file" in err
    monkeypatch.setattr(loops, "missing_web_packages", lambda: ["bokeh"])
    status, _, err = run(capsys, "loops", recording, "--load", "450N", "--report",
                         tmp_path / "r.html")  # fmt: skip
    assert status == 2 and err == (
        'ecofmaps: error: the web pages need Bokeh and Panel: pip install "ecofmaps[web]"\n'
    )
    assert list(tmp_path.iterdir()) == []


# --- in the browser ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def opened(browser, page):
    """The report, opened from file:// (its first table rows drawn)."""
    browser.get(page.as_uri())
    wait_for(lambda: deep_texts(browser, ".slick-row"))
    return browser


def test_the_page_loads_without_console_errors(opened):
    assert console_errors(opened) == []


def test_the_plots_are_drawn(opened):
    canvases = wait_for(lambda: [c for c in opened.execute_script(CANVAS_INK) if c[2] > 1000])
    assert len(canvases) >= 3  # friction over the cycles, the flags, the loops


def test_the_table_shows_the_numbers_of_the_csv(opened, command):
    rows = list(csv.DictReader(io.StringIO(command[0].read_text())))
    columns = list(rows[0])
    shown = deep_texts(opened, ".slick-row")
    assert len(shown) >= 5
    cells = opened.execute_script(
        """
        // The frozen first column and the others are drawn as two rows at the same height.
        const rows = new Map();
        (function visit(root) {
            root.querySelectorAll('.slick-row').forEach(r => {
                const cells = Array.from(r.querySelectorAll('.slick-cell')).map(c => c.textContent);
                rows.set(r.style.top, (rows.get(r.style.top) || []).concat(cells));
            });
            root.querySelectorAll('*').forEach(e => { if (e.shadowRoot) visit(e.shadowRoot); });
        })(document);
        return Array.from(rows.values());
        """
    )
    by_cycle = {row["cycle"]: row for row in rows}
    compared = 0
    for texts in cells:
        assert len(texts) == len(columns)
        expected = by_cycle[texts[0].strip()]
        for column, text in zip(columns, texts, strict=True):
            text, wanted = text.strip(), expected[column]
            try:  # the CSV's number to the column's decimals
                decimals = len(text.partition(".")[2])
                assert float(text) == round(float(wanted), decimals), (column, text, wanted)
            except ValueError:  # text columns, and NaN: an empty field in the CSV
                assert text == wanted, (column, text, wanted)
            compared += 1
    assert compared >= 5 * len(columns)
    for index, column in enumerate(columns):  # the same decimals down each column of numbers
        decimals = {len(t[index].strip().partition(".")[2]) for t in cells if "." in t[index]}
        assert len(decimals) <= 1, (column, decimals)


def test_every_column_of_the_table_is_visible_at_1400_px(opened):
    """In a window 1400 px wide the table's columns all fit, and its first column is frozen."""
    opened.set_window_size(1400, 900)
    right = opened.execute_script(
        """
        let right = 0;
        (function visit(root) {
            root.querySelectorAll('.slick-header-column').forEach(h =>
                right = Math.max(right, h.getBoundingClientRect().right));
            root.querySelectorAll('*').forEach(e => { if (e.shadowRoot) visit(e.shadowRoot); });
        })(document);
        return right;
        """
    )
    assert 0 < right <= opened.execute_script("return document.documentElement.clientWidth;")


def test_the_table_has_its_first_column_frozen_and_fixed_decimals(results):
    """More columns than fit scroll beside the frozen first one; each column of numbers has one
    number of decimals, that of its largest value with 6 significant digits."""
    from bokeh.models import DataTable

    (grid,) = report_document(results).select({"type": DataTable})
    assert grid.frozen_columns == 1 and grid.columns[0].field == "cycle"
    templates = {c.field: getattr(c.formatter, "template", "") for c in grid.columns}
    largest = float(np.nanmax(np.abs(results.ecof.values)))
    assert largest < 1 and "toFixed(6)" in templates["ecof"]  # 0.800030, not 0.80003
    assert "toFixed(4)" in templates["amplitude_um"]  # 50.1348 µm


def test_picking_a_cycle_shows_its_loop(opened):
    opened.execute_script(
        "Bokeh.documents[0].get_model_by_name('loop-picker').value = ['cycle 2', 'cycle 30'];"
    )
    shown = "return Bokeh.documents[0].get_model_by_name('shown-loops').data.label;"
    wait_for(lambda: list(opened.execute_script(shown)) == ["cycle 2", "cycle 30"], timeout=10)
    assert console_errors(opened) == []

"""Correction tables as labs write them: ';' with decimal commas, tabs, '#' comment lines."""

import pytest

from ecofmaps.correction.tables import TableError, correct_table

COMMA = "ecof,amplitude_um,load_N,stiffness_MN_per_m,aspect_ratio\n0.8308,50,450,35,0.2\n"


def written(tmp_path, text, name="table.csv"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def cells(text, delimiter):
    return [line.split(delimiter) for line in text.splitlines()]


def test_semicolons_decimal_commas_and_comments_give_the_comma_table_s_results(tmp_path):
    reference, _ = correct_table(written(tmp_path, COMMA, "comma.csv"))
    mu, factor = cells(reference, ",")[1][-2:]  # the paper's Example 2: mu = 0.8
    assert float(mu) == pytest.approx(0.8, abs=1e-5)
    lab = (
        "# rig 2, specimens of batch 7\n"
        "   # indented comment\n"
        "ecof;amplitude_um;load_N;stiffness_MN_per_m;aspect_ratio;note\n"
        "# first series\n"
        "0,8308;50;450;35;0,2;ball, worn\n"
    )
    text, rows = correct_table(written(tmp_path, lab))
    assert rows == 1
    header, row = cells(text, ";")
    assert header[-2:] == ["mu", "correction_factor"]
    assert row[:6] == ["0,8308", "50", "450", "35", "0,2", "ball, worn"]  # as written
    assert row[-2:] == [mu.replace(".", ","), factor.replace(".", ",")]


def test_tabs_and_semicolons_without_decimal_commas(tmp_path):
    reference, _ = correct_table(written(tmp_path, COMMA, "comma.csv"))
    tabs = COMMA.replace(",", "\t").replace("0.8308", "# comment\n0.8308", 1)
    text, _ = correct_table(written(tmp_path, tabs, "tabs.tsv"))
    assert cells(text, "\t") == cells(reference, ",")
    semicolons = COMMA.replace(",", ";")
    text, _ = correct_table(written(tmp_path, semicolons, "semi.csv"))
    assert cells(text, ";") == cells(reference, ",")  # decimal points stay points


@pytest.mark.parametrize(("separator", "other"), [("\t", ";"), (";", ","), (",", " ")])
def test_the_separator_is_a_tab_else_a_semicolon_else_a_comma(tmp_path, separator, other):
    table = COMMA.replace(",", separator).replace(
        "aspect_ratio", f"aspect_ratio{separator}x{other}y"
    )
    text, _ = correct_table(written(tmp_path, table.replace("0.2", f"0.2{separator}z")))
    assert cells(text, separator)[0][-3:] == [f"x{other}y", "mu", "correction_factor"]


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        # Comment and blank lines count in the line numbers.
        ("# c\n\necof;amplitude_um;load_N;stiffness_MN_per_m;aspect_ratio\n# c\n"
         "0,8;50;450;35;0,2\n0,8;fifty;450;35;0,2\n", 6, "amplitude_um = 'fifty' is not a number"),
        ("ecof;amplitude_um;load_N;stiffness_MN_per_m;aspect_ratio\n0,8;50;450;35\n", 2,
         "4 fields, but the header has 5 columns"),
        ("ecof;amplitude_um;load_N;stiffness_MN_per_m;aspect_ratio\n0,8;50;450;35;-0,2\n", 2,
         "aspect_ratio must satisfy"),
        ("ecof;amplitude_um;load_N;stiffness_MN_per_m;aspect_ratio\n1,2,3;50;450;35;0,2\n", 2,
         "ecof = '1,2,3' is not a number"),
        ("# only comments\n#\n", 1, "the file is empty"),
        ("# c\necof;amplitude_um;load_N;stiffness_MN_per_m;aspect_ratio\n# c\n", 2,
         "header but no data rows"),
        ("ecof amplitude_um load_N\n0.8 50 450\n", 1, "missing column(s)"),
        # A decimal comma in a comma-separated table splits the cell.
        (COMMA + "0,83,50,450,35,0.2\n", 3, "6 fields, but the header has 5 columns"),
    ],
)  # fmt: skip
def test_errors_still_name_file_and_line(tmp_path, text, line, message):
    path = written(tmp_path, text)
    with pytest.raises(TableError) as error:
        correct_table(path)
    assert f"{path}, line {line}: " in str(error.value)
    assert message in str(error.value)

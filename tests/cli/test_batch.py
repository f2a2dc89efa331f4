"""A batch of recordings goes on past one that cannot be analysed."""

import numpy as np
import pandas as pd
import pytest

from ecofmaps.measured.synthetic import synthetic_recording
from ecofmaps.paper import EXAMPLE_2 as POINT
from tests.cli.commands import run_loops as run
from tests.recordings import write_csv


def _batch(folder, broken):
    """Five recordings of a damper test; those in ``broken`` have no usable cycle (the
    displacement does not oscillate)."""
    paths = []
    for index in range(5):
        displacement, force = synthetic_recording(**POINT, cycles=4, seed=index)
        if index in broken:
            displacement = np.full_like(displacement, 1e-6)
        paths.append(write_csv(folder / f"damper{index}.csv", displacement, force))
    return paths


@pytest.mark.slow
def test_one_bad_file_does_not_stop_the_batch(tmp_path, capsys):
    paths = _batch(tmp_path, broken={2})
    out = tmp_path / "results.csv"
    status, printed, err = run(capsys, *paths, "--load", "450N", "--out", out)
    assert status == 1
    table = pd.read_csv(out)
    assert sorted(set(table.file)) == [str(p) for i, p in enumerate(paths) if i != 2]
    assert len(table) == 4 * 4  # four whole cycles in each of the four good files
    errors = [line for line in err.splitlines() if "error" in line]
    assert len(errors) == 1 and str(paths[2]) in errors[0]
    assert "not analysed (1)" in printed and "damper2.csv" in printed


def test_a_batch_where_every_file_fails_writes_nothing(tmp_path, capsys):
    paths = _batch(tmp_path, broken={0, 1, 2, 3, 4})
    out = tmp_path / "results.csv"
    status, _, err = run(capsys, *paths, "--load", "450N", "--out", out)
    assert status == 1 and "none of the 5 recordings" in err
    assert err.count("ecofmaps loops: error:") == 5
    assert not out.exists() and not list(tmp_path.glob(".results.csv*"))


def test_a_single_bad_file_is_an_error(tmp_path, capsys):
    (path,) = _batch(tmp_path, broken={0})[:1]
    status, _, err = run(capsys, path, "--load", "450N", "--out", tmp_path / "r.csv")
    assert status == 2 and str(path) in err
    assert not (tmp_path / "r.csv").exists()

"""``ecofmaps figures`` in parallel and cached: groups of figures, processes, caches."""

import os
import subprocess
import sys

import jax
import numpy as np
import pytest
import xarray as xr

from ecofmaps import figures
from ecofmaps.cli import main
from ecofmaps.cli.figures import TaskQueue
from ecofmaps.figures import recipes
from ecofmaps.io.files import MANIFEST
from ecofmaps.maps import cache_entries
from ecofmaps.maps.cache import JAX_CACHE_FOLDER


def test_groups_share_a_dataset_costliest_first():
    groups = figures.figure_groups()
    assert groups[0] == ["shapes"]  # the costliest: started first
    assert ["fig5", "fig6"] in groups and ["fig7a", "fig7b", "fig8"] in groups
    assert sorted(name for group in groups for name in group) == sorted(figures.FIGURES)
    assert figures.figure_groups(["fig8", "fig7a", "fig8"]) == [["fig8", "fig7a"]]
    with pytest.raises(ValueError, match="unknown figure 'fig9'"):
        figures.figure_groups(["fig9"])


def test_the_shapes_dataset_is_cached(tmp_path, monkeypatch):
    """Computed once, then read from the cache (it was recomputed on every run before)."""
    monkeypatch.setenv("ECOFMAPS_CACHE", str(tmp_path))
    calls = []

    def computed():
        calls.append(1)
        return xr.Dataset({"ecof": ("shape", np.array([1.0, 2.0]))}, coords={"shape": ["a", "b"]})

    monkeypatch.setattr(recipes, "scar_shapes_dataset", computed)
    first = figures.FIGURES["shapes"].data()
    second = figures.FIGURES["shapes"].data()
    assert len(calls) == 1
    xr.testing.assert_identical(first, second)
    assert [entry.function for entry in cache_entries()] == ["scar_shapes"]


def test_the_shapes_key_follows_the_sources():
    """An edit of the recipe or of the correction gives another key (the file's hash)."""
    recipe = recipes.source_digest(["figures/recipes.py"])
    both = recipes.source_digest(["figures/recipes.py", "correction/*.py"])
    assert recipe.dtype == np.uint8 and recipe.shape == (32,)
    assert not np.array_equal(recipe, both)
    np.testing.assert_array_equal(recipe, recipes.source_digest(["figures/recipes.py"]))


def test_the_loops_of_figures_5_and_6_are_cached(tmp_path, monkeypatch):
    monkeypatch.setenv("ECOFMAPS_CACHE", str(tmp_path))
    import ecofmaps.maps.grid

    calls = []
    original = ecofmaps.maps.grid.compute_loops

    def counted(**inputs):
        calls.append(1)
        return original(**inputs)

    monkeypatch.setattr(ecofmaps.maps.grid, "compute_loops", counted)
    first = figures.FIGURES["fig5"].data()
    xr.testing.assert_identical(first, figures.FIGURES["fig6"].data())
    assert len(calls) == 1
    assert [entry.function for entry in cache_entries()] == ["compute_loops"]


@pytest.mark.slow
def test_parallel_command_writes_every_figure(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["figures", "--out", str(out), "--only", "fig8", "fig11a", "--jobs", "2"]) == 0
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "fig11a.png", "fig8.png"]
    progress = capsys.readouterr().err.splitlines()
    assert progress[0].endswith(", 2 processes")
    assert sorted(line.split()[1] for line in progress[1:3]) == ["fig11a", "fig8"]
    assert progress[-1].startswith("done in")


@pytest.mark.parametrize("jobs", ["0", "two", "-1"])
def test_command_rejects_bad_jobs(tmp_path, capsys, jobs):
    assert main(["figures", "--out", str(tmp_path), "--jobs", jobs]) == 2
    err = capsys.readouterr().err
    assert "whole number of processes >= 1" in err and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_command_keeps_jax_kernels_in_the_cache_for_the_run_only(tmp_path, capsys):
    """In this process: the kernels go to <cache>/jax, and JAX's options are restored."""
    before = jax.config.jax_compilation_cache_dir
    assert main(["figures", "--out", str(tmp_path), "--only", "fig8", "--jobs", "1"]) == 0
    assert jax.config.jax_compilation_cache_dir == before
    assert (tmp_path / "fig8.png").exists()
    capsys.readouterr()


@pytest.mark.slow
def test_a_fresh_process_stores_its_compiled_kernels(tmp_path):
    """A run from an empty cache leaves JAX's kernels in <cache>/jax; the second reuses them."""
    cache = tmp_path / "cache"
    environment = {**os.environ, "ECOFMAPS_CACHE": str(cache)}
    command = [sys.executable, "-m", "ecofmaps.cli", "figures", "--out", str(tmp_path / "out"),
               "--only", "universal", "--jobs", "1"]  # fmt: skip
    subprocess.run(command, env=environment, check=True, timeout=600, capture_output=True)
    kernels = sorted(p.name for p in (cache / JAX_CACHE_FOLDER).iterdir())
    assert any(name.startswith("jit__universal_kernel") for name in kernels)
    command.append("--overwrite")  # the figure it wrote: replaced
    subprocess.run(command, env=environment, check=True, timeout=600, capture_output=True)
    assert sorted(p.name for p in (cache / JAX_CACHE_FOLDER).iterdir()) == kernels


def test_the_shapes_dataset_has_parts_computed_first():
    """The model on the scars and the parabola, computed (and cached) in parallel before the
    figure is drawn."""
    parts = figures.figure_parts()
    assert len(parts) == len(figures.figure_groups())
    assert [part.__name__ for part in parts[0]] == ["_scar_shape_model", "_scar_shape_parabola"]
    assert all(not group_parts for group_parts in parts[1:])
    assert figures.figure_parts(["fig8", "fig7a"]) == [[]]


def test_a_group_whose_parts_are_done_is_drawn_next():
    """Never more work started than processes: the shapes figure, once its parts are in the
    cache, is drawn before the groups that were waiting (it was queued behind them)."""
    groups = figures.figure_groups()
    queue = TaskQueue(groups, figures.figure_parts(), jobs=2)
    started = queue.started()
    assert [task[0] for task in started] == ["part", "part"]
    after_first = queue.finished(started[0])
    assert [task[2] for task in after_first] == [groups[1]]
    assert [task[2] for task in queue.finished(started[1])] == [["shapes"]]
    rest = []
    for task in [*after_first, ("group", 0, ["shapes"])]:
        rest += queue.finished(task)
    while rest:
        rest += queue.finished(rest.pop(0))
    assert queue.running == 0 and not queue.ready

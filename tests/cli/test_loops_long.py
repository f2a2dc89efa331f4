"""``ecofmaps loops`` on long tests: missing samples, out of core (threads, two worker
processes), blocks kept as they complete and a resumed run, damaged files and clusters that
do not answer."""

import re

import numpy as np
import pytest

from ecofmaps.measured.synthetic import synthetic_recording, write_long_recording
from ecofmaps.paper import EXAMPLE_2 as POINT
from tests.cli.commands import run_loops as run
from tests.recordings import write_csv


@pytest.fixture(scope="module")
def long_test(tmp_path_factory):
    """A long synthetic test of 60 cycles as zarr and TDMS, and its table in memory."""
    folder = tmp_path_factory.mktemp("long")
    paths = {}
    for suffix in (".zarr", ".tdms"):
        paths[suffix] = write_long_recording(
            folder / f"test{suffix}", cycles=60, samples_per_cycle=100, chunk_samples=700
        )
    return paths


def in_memory_table(capsys, path, tmp_path):
    """The table of ``path`` analysed in memory, and the summary printed under 'wrote'."""
    status, printed, err = run(capsys, path, "--load", "450N", "--out", tmp_path / "memory.csv")
    assert status == 0, err
    return (tmp_path / "memory.csv").read_text(), printed.splitlines()[1:]


def test_missing_cells_are_skipped_and_named(tmp_path, capsys):
    displacement, force = synthetic_recording(**POINT, cycles=6)
    path = write_csv(tmp_path / "gaps.csv", displacement, force)
    lines = path.read_text().splitlines()
    # line 1 is a comment, line 2 the header: sample k is on line k + 3
    lines[350 + 2] = lines[350 + 2].split(",")[0] + ","  # an empty force cell
    lines[900 + 2] = "nan," + lines[900 + 2].split(",")[1]
    path.write_text("\n".join(lines) + "\n")
    status, out, err = run(capsys, path, "--load", "450N", "--out", tmp_path / "r.csv")
    assert status == 0, err
    assert "2 skipped for missing samples (the first at line 353)" in out
    table = (tmp_path / "r.csv").read_text().splitlines()
    assert len(table) == 1 + 6
    assert sum(",invalid," in row for row in table) == 2
    status, out, err = run(
        capsys, path, "--load", "450N", "--out", tmp_path / "s.csv", "--nan-policy", "raise"
    )
    assert status == 2
    assert f"{path}, line 353: missing sample" in err and "--nan-policy skip" in err
    assert not (tmp_path / "s.csv").exists()


@pytest.mark.parametrize("suffix", [".zarr", ".tdms"])
def test_out_of_core_gives_the_table_in_memory(long_test, tmp_path, capsys, small_tasks, suffix):
    expected, summary = in_memory_table(capsys, long_test[suffix], tmp_path)
    out = tmp_path / "long.csv"
    status, printed, err = run(capsys, long_test[suffix], "--load", "450N", "--out", out,
                               "--resume")  # fmt: skip
    assert status == 0, err
    assert out.read_text() == expected
    assert printed.splitlines()[1:] == summary and "ΣE_d = " in summary[1]
    assert "wrote" in printed and not (tmp_path / "long.csv.partial").exists()
    assert err == ""  # not a terminal: no progress bar


def test_several_files_out_of_core(long_test, tmp_path, capsys, small_tasks):
    """Each file's lines are made where its blocks ran, named in the first column."""
    files = (long_test[".zarr"], long_test[".tdms"])
    status, _, err = run(capsys, *files, "--load", "450N", "--out", tmp_path / "memory.csv")
    assert status == 0, err
    out = tmp_path / "long.csv"
    status, _, err = run(capsys, *files, "--load", "450N", "--out", out, "--resume")
    assert status == 0, err
    assert out.read_text() == (tmp_path / "memory.csv").read_text()
    assert out.read_text().startswith("file,cycle,")


@pytest.mark.slow
def test_two_worker_processes(long_test, tmp_path, capsys):
    expected, _ = in_memory_table(capsys, long_test[".tdms"], tmp_path)
    out = tmp_path / "workers.csv"
    status, _, err = run(capsys, long_test[".tdms"], "--load", "450N", "--out", out,
                         "--workers", "2")  # fmt: skip
    assert status == 0, err
    assert out.read_text() == expected


@pytest.fixture(params=["workers", "scheduler"])
def runner_options(request):
    """``--workers 1`` (its tasks keep their blocks where they run), or ``--scheduler`` of a
    cluster at an address (this process keeps them: the workers may not see its files)."""
    if request.param == "workers":
        yield ["--workers", "1"]
        return
    from distributed import LocalCluster

    with LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
        yield ["--scheduler", cluster.scheduler_address]


@pytest.mark.slow
def test_an_interrupted_run_resumes(
    long_test, tmp_path, capsys, small_tasks, on_each_block, runner_options
):
    """Ctrl-C after two blocks have come back: nothing at --out, the blocks done kept (two,
    or more that were running) and counted; a rerun must say --resume; with it, the table
    of an uninterrupted run."""
    expected, _ = in_memory_table(capsys, long_test[".zarr"], tmp_path)
    out = tmp_path / "r.csv"

    def interrupting(received):
        if len(received) == 2:
            raise KeyboardInterrupt

    on_each_block(interrupting)
    status, _, err = run(capsys, long_test[".zarr"], "--load", "450N", "--out", out,
                         *runner_options)  # fmt: skip
    assert status == 130
    partial = tmp_path / "r.csv.partial"
    kept = sorted(path.name for path in partial.glob("file0-block*.npz"))
    assert 2 <= len(kept) < 6 and kept[:2] == ["file0-block000000.npz", "file0-block000001.npz"]
    assert f"{len(kept)} of 6 blocks" in err and "--resume" in err
    assert not out.exists()
    on_each_block(None)
    status, _, err = run(capsys, long_test[".zarr"], "--load", "450N", "--out", out)
    assert status == 2 and "holds an unfinished run: add --resume" in err
    status, _, err = run(capsys, long_test[".zarr"], "--load", "400N", "--out", out, "--resume")
    assert status == 2 and "holds a run of other files or options" in err
    assert not list(tmp_path.glob(".r.csv.*"))  # nor its temporary
    (partial / kept[0]).unlink()  # the first block is measured again, after those kept
    status, _, err = run(capsys, long_test[".zarr"], "--load", "450N", "--out", out, "--resume")
    assert status == 0, err
    assert out.read_text() == expected
    assert not partial.exists()


def interrupted(capsys, on_each_block, path, out):
    """``ecofmaps loops path --out out --resume`` stopped by Ctrl-C after two blocks."""

    def interrupting(received):
        if len(received) == 2:
            raise KeyboardInterrupt

    on_each_block(interrupting)
    status, _, err = run(capsys, path, "--load", "450N", "--out", out, "--resume")
    on_each_block(None)
    assert status == 130, err


def test_resume_sees_a_recording_changed_in_place(long_test, tmp_path, capsys, small_tasks,
                                                  on_each_block):  # fmt: skip
    """The force scaled in place in the store's chunks (its folder's size and time kept):
    the run kept is not resumed on it."""
    import shutil

    import zarr

    store = tmp_path / "test.zarr"
    shutil.copytree(long_test[".zarr"], store)
    out = tmp_path / "r.csv"
    interrupted(capsys, on_each_block, store, out)
    group = zarr.open_group(store, mode="r+")
    group["force"][:] = group["force"][:] * 1.5
    status, _, err = run(capsys, store, "--load", "450N", "--out", out, "--resume")
    assert status == 2 and "holds a run of other files" in err and "delete it" in err
    assert not out.exists()


def test_resume_refuses_a_run_of_another_format(long_test, tmp_path, capsys, small_tasks,
                                               on_each_block):  # fmt: skip
    """A run folder written by an ecofmaps whose stored cycles lack a field of today's is
    named as a run of another ecofmaps, not loaded (a KeyError, 'a bug')."""
    import json

    out = tmp_path / "r.csv"
    interrupted(capsys, on_each_block, long_test[".zarr"], out)
    partial = tmp_path / "r.csv.partial"
    record = json.loads((partial / "run.json").read_text())
    (partial / "run.json").write_text(json.dumps({**record, "format": 3}))
    with np.load(partial / "file0-cycles.npz") as stored:
        older = {k: v for k, v in stored.items() if k != "hidden"}
    np.savez(partial / "file0-cycles.npz", **older)
    status, _, err = run(capsys, long_test[".zarr"], "--load", "450N", "--out", out, "--resume")
    assert status == 2 and "of another ecofmaps" in err and "delete it" in err
    assert "bug" not in err and not out.exists()


def _resaved_doubled(blocks, partial):
    with np.load(blocks[0]) as stored:
        values = {k: v * 2 if k.startswith("v:") and v.dtype.kind == "f" else v
                  for k, v in stored.items()}  # fmt: skip
    with open(blocks[0], "wb") as stream:
        np.savez(stream, **values)
    return {blocks[0].name: "changed since it was kept"}


def _swapped(blocks, partial):
    swap = partial / "swap.npz"
    blocks[0].rename(swap)
    blocks[1].rename(blocks[0])
    swap.rename(blocks[1])
    return {b.name: "changed since it was kept" for b in blocks[:2]}


def _extra(blocks, partial):
    (partial / "file0-block000042.npz").write_bytes(blocks[0].read_bytes())
    (partial / "file0-block000005.npz").write_bytes(blocks[1].read_bytes())
    return {
        "file0-block000042.npz": "is beyond the run's 6 blocks",
        "file0-block000005.npz": "is not in the run's record",
    }


@pytest.mark.parametrize("tamper", [_resaved_doubled, _swapped, _extra])
def test_a_kept_block_that_fails_its_check_is_measured_again(
    long_test, tmp_path, capsys, small_tasks, on_each_block, tamper
):
    """Each kept block is checked against the checksum and the cycle rows the run recorded
    of it: one re-saved with its values doubled, two swapped, one added are each measured
    again, with a line that names it, and the table is right."""
    expected, _ = in_memory_table(capsys, long_test[".zarr"], tmp_path)
    out = tmp_path / "r.csv"
    interrupted(capsys, on_each_block, long_test[".zarr"], out)
    partial = tmp_path / "r.csv.partial"
    blocks = sorted(partial.glob("file0-block*.npz"))[:2]
    refused = tamper(blocks, partial)
    status, _, err = run(capsys, long_test[".zarr"], "--load", "450N", "--out", out, "--resume")
    assert status == 0, err
    assert out.read_text() == expected
    for name, reason in refused.items():
        assert f"{partial / name} {reason}" in err and "measured again" in err
    assert err.count("\n") == len(refused)


@pytest.mark.parametrize("damage", ["not json", "[" * 100_000 + "]" * 100_000])
def test_a_damaged_record_of_the_run_is_named_as_such(
    long_test, tmp_path, capsys, small_tasks, on_each_block, damage
):
    """run.json garbled or nested 100,000 deep: the record is named as damaged, with the
    remedy (not a bug, nor a run of other files); a deep line in kept.jsonl is passed over."""
    out = tmp_path / "r.csv"
    interrupted(capsys, on_each_block, long_test[".zarr"], out)
    partial = tmp_path / "r.csv.partial"
    with open(partial / "kept.jsonl", "a") as kept:
        kept.write(damage + "\n")
    expected, _ = in_memory_table(capsys, long_test[".zarr"], tmp_path)
    status, _, err = run(capsys, long_test[".zarr"], "--load", "450N", "--out", out, "--resume")
    assert status == 0, err
    assert out.read_text() == expected
    out.unlink()
    interrupted(capsys, on_each_block, long_test[".zarr"], out)
    (partial / "run.json").write_text(damage)
    status, _, err = run(capsys, long_test[".zarr"], "--load", "450N", "--out", out, "--resume")
    assert status == 2
    assert f"{partial / 'run.json'} is missing or damaged" in err and "delete the folder" in err


def test_the_table_is_written_as_the_blocks_come(long_test, tmp_path, capsys, small_tasks,
                                                 on_each_block):  # fmt: skip
    """Each block's lines are in the temporary file beside --out (in order, after the header)
    once the block has come back, not held to the end; the file lands whole."""
    expected, _ = in_memory_table(capsys, long_test[".zarr"], tmp_path)
    out = tmp_path / "r.csv"
    seen = []

    def watching(received):
        (temporary,) = tmp_path.glob(".r.csv.*.tmp")
        seen.append((sum(received), temporary.read_text()))

    on_each_block(watching)
    status, _, err = run(
        capsys, long_test[".zarr"], "--load", "450N", "--out", out, "--resume"
    )  # --resume: read lazily, though short
    assert status == 0, err
    assert out.read_text() == expected
    assert len(seen) == 6
    lines = expected.splitlines(keepends=True)
    for cycles, text in seen:
        assert text == "".join(lines[: 1 + cycles])


def damaged(path, tmp_path):
    """A copy of ``path`` cut short (a file) or missing a chunk (a zarr store)."""
    import shutil

    copy = tmp_path / f"cut{path.suffix}"
    if path.is_dir():
        shutil.copytree(path, copy)
        next(iter(sorted((copy / "force" / "c").iterdir()))).unlink()
    else:
        data = path.read_bytes()
        copy.write_bytes(data[: len(data) * 2 // 3])
    return copy


@pytest.mark.parametrize(
    ("case", "message"),
    [
        (".zarr", r"cut.zarr, variable 'force': 1 of its \d+ chunks are missing"),
        (".tdms", r"cut.tdms: truncated or damaged TDMS file"),
        (".h5", r"cut.h5: cannot open as HDF5 \(truncated or damaged"),
        ("no channel", r"test.zarr: no force variable 'friction'"),
        ("short channel", r"short.h5, variable 'force': 5000 samples where the displacement"),
        ("no scheduler", r"no dask scheduler at tcp://127\.0\.0\.1:9: .* after 1 s"),
    ],
)
def test_bad_input_leaves_nothing(long_test, tmp_path, capsys, monkeypatch, case, message):
    import h5py

    monkeypatch.setattr("ecofmaps._parallel.CONNECT_TIMEOUT", 1.0)
    arguments = ["--load", "450N", "--out", tmp_path / "r.csv", "--resume"]
    if case == ".h5":
        path = write_long_recording(tmp_path / "test.h5", cycles=60, samples_per_cycle=100)
        path = damaged(path, tmp_path)
    elif case in (".zarr", ".tdms"):
        path = damaged(long_test[case], tmp_path)
    elif case == "no channel":
        path, arguments = long_test[".zarr"], [*arguments, "--force-col", "friction"]
    elif case == "short channel":
        path = tmp_path / "short.h5"
        with h5py.File(path, "w") as handle:
            handle["displacement"] = np.zeros(6000)
            handle["force"] = np.zeros(5000)
    else:
        path, arguments = long_test[".zarr"], [*arguments, "--scheduler", "tcp://127.0.0.1:9"]
    status, _, err = run(capsys, path, *arguments)
    assert status == 2
    assert re.search(message, err), err
    assert list(tmp_path.glob("r.csv*")) == []


def test_convert_a_csv_file_then_analyse_it(tmp_path, capsys):
    """``ecofmaps convert`` keeps every sample (in SI) and the cycle column: the same table."""
    from ecofmaps.cli import main
    from ecofmaps.measured.synthetic import example_path

    store = tmp_path / "example.zarr"
    assert main(["convert", str(example_path()), str(store), "--chunk-samples", "5000"]) == 0
    assert "24000 samples of displacement, force, cycle" in capsys.readouterr().out
    assert main(["convert", str(example_path()), str(store)]) == 2
    assert "exists already: --overwrite" in capsys.readouterr().err
    tables = []
    for path in (example_path(), store):
        status, _, err = run(capsys, path, "--load", "450N", "--out", tmp_path / "r.csv",
                             "--resume")  # fmt: skip
        assert status == 0, err
        tables.append((tmp_path / "r.csv").read_text())
        (tmp_path / "r.csv").unlink()
    assert tables[0] == tables[1]

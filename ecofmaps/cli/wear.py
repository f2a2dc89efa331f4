"""``ecofmaps wear``: energy wear of fretting tests from their results tables and scar profiles.

Each test's per-cycle table (as ``ecofmaps loops --out`` writes it, CSV or netCDF) and its
wear-scar profile (a profilometer trace, as ``ecofmaps model --scar-profile`` reads it) give
ΣE_d, the wear volume of a line contact, the energy wear coefficient α and Archard's k, with
the test's sliding condition; over several tests, α and the threshold energy E_th. The
method is in docs/lab.md.
"""

from __future__ import annotations

import argparse

from ecofmaps.cli._common import quantity, unit

__all__ = ["add", "run"]

#: The per-test numbers, in the order printed and written.
_WEAR = (
    "cumulated_energy",
    "wear_volume",
    "energy_wear_coefficient",
    "archard_slip",
    "archard_nominal",
)


def _length_with_unit(text: str) -> float:
    """``--length``: a length that must carry its unit (``5mm``)."""
    try:
        float(text)
    except ValueError:
        return quantity("scar_half_width")(text)
    raise argparse.ArgumentTypeError(f"{text!r} has no unit: give the contact's length as 5mm")


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "wear",
        help="energy wear coefficient and Archard's k from results tables and scar profiles",
        description=(
            "Energy wear of fretting tests: for each test, the dissipated energy summed over "
            "its cycles (the recorded ones, every N-th, with the cycles between them), the "
            "wear volume of a line contact (the scar's worn area times --length, the pile-up "
            "apart), the energy wear coefficient α = V/ΣE_d, Archard's k on the slip and on "
            "the applied amplitude, each with its standard error, and the sliding condition; "
            "over several tests, α and the threshold energy E_th of V = α(ΣE_d - E_th). Give "
            "one --profile per test, in the order of the tests (a table of several "
            "recordings holds several tests)."
        ),
    )
    parser.add_argument(
        "tables", nargs="+", metavar="TABLE", help="results of ecofmaps loops (CSV, or netCDF .nc)"
    )
    parser.add_argument(
        "--profile",
        action="append",
        required=True,
        metavar="FILE",
        help="a test's wear-scar profile (x and z columns); once per test",
    )
    parser.add_argument(
        "--length",
        type=_length_with_unit,
        required=True,
        metavar="L",
        help="length of the line contact, with its unit, e.g. 5mm",
    )
    parser.add_argument(
        "--rig-stiffness",
        type=quantity("stiffness"),
        metavar="S",
        help="the rig's own stiffness, e.g. 35MN/m: the sliding condition is "
        "then read on the contact's displacement",
    )
    parser.add_argument(
        "--x-unit",
        type=unit("length"),
        metavar="UNIT",
        help="unit of the profiles' positions (default: the column's, else um)",
    )
    parser.add_argument(
        "--z-unit",
        type=unit("length"),
        metavar="UNIT",
        help="unit of the profiles' heights (default: the column's, else um)",
    )
    parser.add_argument("--out", metavar="OUT", help="write the numbers here (CSV)")
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace --out if ecofmaps wrote it (never a user's file)",
    )
    parser.set_defaults(handler=run)


def _column(name: str) -> str:
    from ecofmaps._nomenclature import column

    return column(name).replace("³", "3").replace("·", "").replace("(", "").replace(")", "")


def _tests(args) -> list:
    """(name, results) of every test in the tables, in order."""
    from ecofmaps.io.tables import read_results

    tests = []
    for path in args.tables:
        found = read_results(path)
        many = len(found) > 1
        tests += [(f"{path}:{r.attrs['file']}" if many else path, r) for r in found]
    return tests


def _profile(args, path):
    """The levelled profile in ``path``; what the reading decided printed on standard error."""
    import sys
    import warnings

    from ecofmaps.io.scar_profiles import read_scar_profile
    from ecofmaps.model.profiles import ScarProfileWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ScarProfileWarning)
        try:
            profile = read_scar_profile(path, x_unit=args.x_unit, z_unit=args.z_unit)
        except ValueError as error:
            text = str(error)
            raise ValueError(text if text.startswith(str(path)) else f"{path}: {text}") from None
    for item in caught:
        print(f"ecofmaps wear: warning: {path}: {item.message.summary}", file=sys.stderr)
    return profile


def run(args) -> int:
    """Run ``ecofmaps wear`` with the parsed ``args``; the exit status."""
    from pathlib import Path

    from ecofmaps.cli._common import CommandError, print_rows, refuse_to_overwrite
    from ecofmaps.io.files import record_written, write_text
    from ecofmaps.io.tables import csv_text
    from ecofmaps.lab import energy_wear, sliding_condition

    if args.out is not None and not Path(args.out).parent.is_dir():
        raise CommandError(f"cannot write {args.out}: its directory does not exist")
    refuse_to_overwrite(
        [("--out", args.out)], [*args.tables, *args.profile], overwrite=args.overwrite
    )
    tests = _tests(args)
    if len(args.profile) != len(tests):
        raise CommandError(
            f"give one --profile per test: {len(tests)} tests in the tables, "
            f"{len(args.profile)} profiles"
        )
    profiles = [_profile(args, path) for path in args.profile]
    rows = []
    for (name, results), path, profile in zip(tests, args.profile, profiles, strict=True):
        try:
            wear = energy_wear(results, profile, length=args.length)
            condition = sliding_condition(results, rig_stiffness=args.rig_stiffness)
        except ValueError as error:
            raise CommandError(f"{name}: {error}") from None
        values = {q: (float(wear[q]), float(wear[f"{q}_se"])) for q in _WEAR}
        rows.append((name, path, condition.attrs["sliding_condition"], values))
        print_rows(
            f"{name} (scar profile {path}, {condition.attrs['sliding_condition']})",
            [_with_se(q, *values[q]) for q in _WEAR],
        )
    if len(tests) > 2:
        fit = energy_wear([r for _, r in tests], profiles, length=args.length)
        names = ("campaign_energy_wear_coefficient", "threshold_energy")
        print_rows(
            "campaign: V = α(ΣE_d - E_th)",
            [_with_se(q, float(fit[q]), float(fit[f"{q}_se"])) for q in names],
        )
    if args.out is not None:
        write_text(args.out, csv_text(_table(rows)))
        record_written([args.out])
        print(f"wrote {args.out}: {len(rows)} tests")
    return 0


def _with_se(name, value, se):
    from ecofmaps.cli._common import row

    words, symbol, shown = row(name, value)
    return words, symbol, f"{shown} ± {row(name, se)[2]}"


def _table(rows):
    import pandas as pd

    from ecofmaps._nomenclature import QUANTITIES

    table = {"test": [r[0] for r in rows], "profile": [r[1] for r in rows],
             "sliding_condition": [r[2] for r in rows]}  # fmt: skip
    for name in _WEAR:
        factor = QUANTITIES[name].display_factor
        table[_column(name)] = [r[3][name][0] * factor for r in rows]
        table[_column(name).replace(name, f"{name}_se")] = [r[3][name][1] * factor for r in rows]
    return pd.DataFrame(table)

"""``ecofmaps wear``: energy wear of fretting tests from their ``ecofmaps loops --out`` tables
and scar profiles (:func:`ecofmaps.energy_wear`, :func:`ecofmaps.transition`, docs/lab.md)."""

from __future__ import annotations

from ecofmaps._nomenclature import TRANSITION, texts_with_se, transition_texts
from ecofmaps.cli import common
from ecofmaps.cli.main import CommandError
from ecofmaps.io.files import record_written, write_text

#: The per-test numbers, in the order printed and written.
_WEAR = (
    *("cumulated_energy", "wear_volume", "energy_wear_coefficient"),
    *("archard_slip", "archard_nominal"),
)

_HELP = {
    "tables": "results of ecofmaps loops (CSV, or .nc)",
    "--profile": "a test's wear-scar profile (x and z columns); once per test",
    "--rig-stiffness": "the rig's own stiffness, e.g. 35MN/m: regime read on the contact",
    "--out": "write the numbers here (CSV)",
}


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "wear",
        help="energy wear coefficient and Archard's k from results tables and scar profiles",
        description="Per test: the dissipated energy summed over every cycle (a rig records every "
        "N-th), the wear volume (a line contact: the worn area times --length; --sphere: the "
        "revolution of the worn depth, both sides averaged; pile-up apart), α = V/ΣE_d, Archard's "
        "k on the slip and on the applied amplitude, each ± its standard error, and the sliding "
        "condition. Over three tests or more: α and E_th of V = α(ΣE_d - E_th), and the "
        "transition to gross slip Δ_t, δ_t, μ_t if they span it (row 'campaign' of --out). "
        "--profile in the tests' order (a table of several recordings holds several tests).",
    )
    option = common.option_adder(parser, _HELP)
    option("tables", nargs="+", metavar="TABLE")
    option("--profile", action="append", required=True, metavar="FILE")
    common.add_contact_options(parser, required=True)
    stiffness = common.quantity("stiffness", option="--rig-stiffness")
    option("--rig-stiffness", type=stiffness, metavar="S")
    option("--x-unit", type=common.unit("length"), metavar="UNIT")
    option("--z-unit", type=common.unit("length"), metavar="UNIT")
    option("--out", metavar="OUT")
    option("--overwrite", action="store_true")


def _columns(found, names, quantity="{}") -> dict:
    """Columns of ``names`` and their standard errors, in the display units, ASCII names."""
    from ecofmaps._nomenclature import QUANTITIES, column

    line = {}
    for name in names:
        q = quantity.format(name)
        label = column(q).replace("³", "3").replace("·", "").replace("(", "").replace(")", "")
        for key, v in ((label, name), (label.replace(q, f"{q}_se"), f"{name}_se")):
            line[key] = float(found[v]) * QUANTITIES[q].display_factor
    return line


def run(args) -> int:
    import pandas as pd

    from ecofmaps.io.tables import csv_text, read_results
    from ecofmaps.lab import energy_wear, sliding_condition, transition

    inputs = [*args.tables, *args.profile]
    common.refuse_to_overwrite([("--out", args.out)], inputs, overwrite=args.overwrite)
    tests = []
    for path in args.tables:
        found = read_results(path)
        tests += [(f"{path}:{r.attrs['file']}" if len(found) > 1 else path, r) for r in found]
    if len(args.profile) != len(tests):
        raise CommandError(
            f"give one --profile per test: {len(tests)} tests in the tables, "
            f"{len(args.profile)} profiles"
        )
    units = (args.x_unit, args.z_unit)
    profiles = [common.read_scar_file(path, "wear", *units) for path in args.profile]
    table = []
    for (name, results), path, profile in zip(tests, args.profile, profiles, strict=True):
        try:
            wear = energy_wear(results, profile, args.length, common.contact(args))
            condition = sliding_condition(results, rig_stiffness=args.rig_stiffness)
        except ValueError as error:
            raise CommandError(f"{name}: {error}") from None
        slip = condition.attrs["sliding_condition"]
        rows = [common.row(q, text) for q, text in texts_with_se(wear, _WEAR)]
        common.print_rows(f"{name} (scar profile {path}, {slip})", rows)
        line = {"test": str(name), "profile": str(path), "sliding_condition": str(slip)}
        table.append(line | _columns(wear, _WEAR))
    if len(tests) > 2:
        fit = energy_wear([r for _, r in tests], profiles, args.length, common.contact(args))
        names = ("campaign_energy_wear_coefficient", "threshold_energy")
        rows = [common.row(q, text) for q, text in texts_with_se(fit, names)]
        common.print_rows("campaign: V = α(ΣE_d - E_th)", rows)
        try:
            found = transition([r for _, r in tests], rig_stiffness=args.rig_stiffness)
        except ValueError as error:
            print(f"campaign: no transition to gross slip: {error}")
        else:
            rows = [common.row(q, text) for q, text in transition_texts(found)]
            common.print_rows("campaign: transition to gross slip", rows)
            campaign = {"test": "campaign", "profile": "", "sliding_condition": ""}
            table.append(campaign | _columns(found, TRANSITION, "transition_{}"))
    if args.out is not None:
        write_text(args.out, csv_text(pd.DataFrame(table)))
        record_written([args.out])
        print(f"wrote {args.out}: {len(tests)} tests")
    return 0

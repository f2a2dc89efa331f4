"""``ecofmaps correct``: reported ECoF values corrected to the contact CoF (a point or a table)."""

from __future__ import annotations

from ecofmaps.cli._common import quantity
from ecofmaps.cli._profile import (
    add_profile_options,
)

__all__ = ["GROOVE_OPTIONS", "POINT_OPTIONS", "add"]

POINT_OPTIONS = ("ecof", "amplitude", "load", "stiffness")
GROOVE_OPTIONS = ("aspect_ratio", "scar_depth", "scar_half_width")


def add(subparsers) -> None:
    parser = subparsers.add_parser(
        "correct",
        help="correct reported ECoF values to the contact CoF (one point or a CSV table)",
        description=(
            "Correct a reported energy coefficient of friction μ_E to the contact CoF μ the "
            "model puts behind it, given the test's amplitude, load and rig stiffness and the "
            "wear scar's depth over half-width z_o/x_o = D/W (eq. 11; x_o = Δ*). One point: "
            "--ecof --amplitude --load --stiffness and --aspect-ratio (or --scar-depth and "
            "--scar-half-width). A table: TABLE.csv with columns ecof, amplitude_um, load_N, "
            "stiffness_MN_per_m and aspect_ratio or scar_depth_um + scar_half_width_um, "
            "separated by commas, semicolons (decimal commas allowed) or tabs, '#' lines "
            "skipped as comments; the output, in the table's own separator, keeps every "
            "column and adds mu and correction_factor. With "
            "--scar-profile FILE a measured wear-scar profile gives the scar instead (of the "
            "point, or of every row of a table, which then has no scar columns), and the "
            "parabola of the same D/W is given beside it (mu_parabolic in a table). A bad "
            "row stops the run, naming the file and line (the header is line 1); nothing is "
            "written then."
        ),
    )
    parser.add_argument(
        "table",
        nargs="?",
        metavar="TABLE",
        help="table of reported ECoFs (',', ';' or tab separated)",
    )
    parser.add_argument(
        "--out", metavar="OUT", default=None,
        help="write the corrected table here (the table's separator; default: standard output)",
    )  # fmt: skip
    parser.add_argument(
        "--overwrite", action="store_true",
        help="replace --out if ecofmaps wrote it; a file ecofmaps did not write is never replaced",
    )  # fmt: skip
    parser.add_argument("--ecof", type=quantity("ecof"), help="reported energy CoF μ_E, e.g. 0.83")
    parser.add_argument(
        "--amplitude", type=quantity("amplitude"), help="displacement amplitude Δ*, e.g. 50um"
    )
    parser.add_argument("--load", type=quantity("load"), help="normal load P, e.g. 450N")
    parser.add_argument(
        "--stiffness", type=quantity("stiffness"),
        help="rig stiffness S, e.g. 35MN/m ('inf' for a rigid rig)",
    )  # fmt: skip
    parser.add_argument(
        "--aspect-ratio", type=quantity("aspect_ratio"),
        help="wear scar depth over half-width z_o/x_o = D/W, e.g. 0.2",
    )  # fmt: skip
    parser.add_argument("--scar-depth", type=quantity("scar_depth"), help="scar depth D, e.g. 8um")
    parser.add_argument(
        "--scar-half-width", type=quantity("scar_half_width"), help="scar half-width W, e.g. 40um"
    )
    add_profile_options(parser)
    parser.set_defaults(handler="ecofmaps.cli.correct_run:run")  # imported when it runs

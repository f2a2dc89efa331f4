"""Running ``ecofmaps`` commands in-process, for the command-line tests."""

from ecofmaps import cli


def run(capsys, *argv):
    """Run the command in-process; return (exit status, stdout, stderr)."""
    try:
        status = cli.main([str(a) for a in argv])
    except SystemExit as stop:  # argparse errors and --help
        status = stop.code
    captured = capsys.readouterr()
    return status, captured.out, captured.err

"""``python -m ecofmaps.cli``: the ``ecofmaps`` command."""

from ecofmaps.cli.main import console

if __name__ == "__main__":
    console()

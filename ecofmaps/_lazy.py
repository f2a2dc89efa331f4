"""The public names of a package, imported from their modules on first use (PEP 562): the
command line starts without loading JAX, xarray, pint or SciPy."""

import importlib
import sys


def lazy_names(package: str, public: dict, submodules=()):
    """``__getattr__``, ``__dir__`` and ``__all__`` for the package ``package``."""
    home = {name: module for module, names in public.items() for name in names}
    namespace = sys.modules[package].__dict__

    def __getattr__(name: str):
        if name in home:  # imported once: a name of the package from then on
            namespace[name] = getattr(importlib.import_module(home[name]), name)
            return namespace[name]
        if name in submodules:
            return importlib.import_module(f"{package}.{name}")
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__():
        return sorted({*namespace, *home, *submodules})

    return __getattr__, __dir__, sorted([*home, *submodules])

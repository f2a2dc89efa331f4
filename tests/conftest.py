"""Shared test set-up: a private cache, a compilation cache, a headless matplotlib,
hypothesis profiles."""

import os
from pathlib import Path

# JAX keeps what it compiles under .pytest_cache (git ignores it), for the test processes and the
# commands they start: a second run, or the other worker of this one, does not compile again.
os.environ.setdefault(
    "JAX_COMPILATION_CACHE_DIR", str(Path(__file__).parents[1] / ".pytest_cache" / "jax")
)
os.environ.setdefault("JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS", "0")
os.environ.setdefault("JAX_PERSISTENT_CACHE_MIN_ENTRY_SIZE_BYTES", "-1")

import jax  # reads the variables above
import pytest
from hypothesis import HealthCheck, settings

os.environ.setdefault("MPLBACKEND", "Agg")

# The tests call the pure-jax.numpy core and jit the public functions themselves, which needs
# JAX's 64-bit mode, as it does for any user who does so. ecofmaps itself never switches it
# on (tests/model/test_steady_state.py checks that, and float64 results with it off).
jax.config.update("jax_enable_x64", True)

# JAX compiles on first call, so a per-example deadline would measure compilation.
settings.register_profile(
    "default", deadline=None, max_examples=60, suppress_health_check=[HealthCheck.too_slow]
)
settings.register_profile("thorough", parent=settings.get_profile("default"), max_examples=1000)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


def pytest_configure(config):
    """A silent regime warning in a test is an error.

    Registered here, not in pyproject.toml: naming the class there makes pytest import
    ecofmaps before it has put the checkout on sys.path, so with a non-editable install (as in
    CI) the installed copy is imported and the doctests of the checkout refuse to collect.
    """
    config.addinivalue_line("filterwarnings", "error::ecofmaps.RegimeWarning")


@pytest.fixture(autouse=True, scope="session")
def _private_cache(tmp_path_factory):
    """Every test writes its cache under a temporary directory, never the user's."""
    previous = os.environ.get("ECOFMAPS_CACHE")
    os.environ["ECOFMAPS_CACHE"] = str(tmp_path_factory.mktemp("ecofmaps-cache"))
    yield
    if previous is None:
        del os.environ["ECOFMAPS_CACHE"]
    else:
        os.environ["ECOFMAPS_CACHE"] = previous


@pytest.fixture
def on_each_block(monkeypatch):
    """``on_each_block(hook)``: ``ecofmaps loops`` calls ``hook(received)`` each time a block
    of a long recording comes back, after its progress bar's update (``received``: the
    cycles of each block so far, this one last); ``on_each_block(None)`` takes it off."""
    from ecofmaps.cli import loops_long  # as the tests import ecofmaps: not at collection

    progress = loops_long._bar

    def install(hook):
        def hooked(*args):
            bar = progress(*args)
            update, received = bar.update, []

            def on_block(cycles):
                update(cycles)
                received.append(cycles)
                hook(received)

            bar.update = on_block
            return bar

        monkeypatch.setattr(loops_long, "_bar", progress if hook is None else hooked)

    return install

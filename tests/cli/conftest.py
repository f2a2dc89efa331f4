"""Fixtures shared by the command-line tests."""

import pytest

from ecofmaps.measured import pipeline


@pytest.fixture
def small_tasks(monkeypatch):
    """Tasks of about 1000 samples: a test of 60 cycles of 100 is six blocks."""
    monkeypatch.setattr(pipeline, "TASK_SAMPLES", 1000)

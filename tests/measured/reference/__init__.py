"""A frozen copy of ``ecofmaps.measured.cycles`` and ``analysis`` as of commit 78c1a42.

It is the reference of ``tests/measured/test_equivalence.py`` only: the blockwise rewrite of
``analyze_loops`` (issue 12, item 6) must give the same per-cycle numbers as this padded
implementation. Do not import it from the package, and do not edit it.
"""

"""Reference values the tests compare the code against, written out
independently of it.

* :mod:`reference.dem`: analytic two-body Hertz results (stiffness,
  peak overlap, contact time), disc masses and the binary-impact set-up
  shared by the tests of the Hertzian floe engine.

Test modules import them explicitly (``from reference.dem import
hertz_contact_time``): the ``tests`` directory is on ``sys.path`` through
``pythonpath`` in ``pyproject.toml`` (and ``tests/conftest.py``).
"""

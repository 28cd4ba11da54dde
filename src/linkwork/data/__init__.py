"""Data bundled with linkwork: the example synthesis problems under ``examples/`` (written by
``examples/make_examples.py``), found with :mod:`importlib.resources` so they work from an installed
package."""

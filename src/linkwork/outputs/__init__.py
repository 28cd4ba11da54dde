"""Writing and summarising results: the files and tables that ``linkwork trace``, ``synth``, ``mechanize`` and
``demo`` produce, as library functions, so that the command line stays a thin layer and scripts, tests and docs
can call them without importing :mod:`linkwork.cli`."""

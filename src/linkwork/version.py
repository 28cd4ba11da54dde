"""linkwork's version (one place; ``linkwork.__version__`` and the kernel cache's key read it)."""

__version__ = "0.1.0"

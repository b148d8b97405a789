"""The version of bidmp (one place: the package, the model files' metadata and the packaging read it)."""

__version__ = "0.6.0"

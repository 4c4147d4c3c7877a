"""The package version, importable from every stage without importing the top level."""

__version__ = "0.1.0"

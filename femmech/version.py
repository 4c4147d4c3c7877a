"""The package version, importable from every stage without importing the top level.

Stage 0: imports nothing of femmech; every module may import it.
"""

__version__ = "0.1.0"

"""The package version, in one place (read by pyproject.toml and written into every table)."""
__version__ = "0.3.0"

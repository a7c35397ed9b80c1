"""Capability commands of the CLI: each module defines ``register(app: typer.Typer)``."""

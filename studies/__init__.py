"""railopt.studies: study kinds driven by TOML, the model catalog, the model → design adapter, the CLI."""

__all__: list[str] = []

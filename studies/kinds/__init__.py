"""Study kinds; each module (or package) registers its kind with :func:`railopt.studies.kind.register_kind`."""

__all__: list[str] = []

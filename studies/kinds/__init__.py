"""Study kinds; each module registers its kind with :func:`railopt.studies.base.register_kind`."""

"""railopt: linear track/train dynamics and minimax suspension design.

The package is split into three layers installed from the top-level folders:
``railopt.models`` (physics), ``railopt.design`` (generic minimax optimisation) and
``railopt.studies`` (configs, wiring, CLI).
"""

__version__ = "0.1.0"

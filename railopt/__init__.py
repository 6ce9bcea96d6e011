"""railopt: linear track/train dynamics and minimax suspension design.

The package is split into three layers installed from the top-level folders:
``railopt.models`` (physics), ``railopt.design`` (generic minimax optimisation) and
``railopt.studies`` (configs, wiring, CLI).
"""

from pkgutil import extend_path

# Python started in a source checkout finds this folder (``./railopt``) before the installed
# package; extending the path lets ``railopt.models`` etc. resolve to the installed copy then.
__path__ = extend_path(__path__, __name__)

__version__ = "0.1.0"

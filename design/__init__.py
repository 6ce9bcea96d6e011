"""Design layer: generic minimax optimisation (never imports the model layer).

``MinimaxProblem`` maps design variables to a vector f_k(x); ``solve`` runs one local method on
the epigraph NLP; ``multistart`` runs many starts (serially or on dask) into a campaign store.
"""

from railopt.design.checks import check_designs
from railopt.design.methods import METHODS
from railopt.design.multistart import distinct_optima, label_clusters, multistart
from railopt.design.parallel import dask_client, map_unordered
from railopt.design.problem import Evaluation, MinimaxProblem
from railopt.design.result import STATUSES, SolveResult
from railopt.design.solve import solve
from railopt.design.starts import start_points
from railopt.design.store import CampaignStore
from railopt.design.surface import Surface, grid_map, objective_surface
from railopt.design.tradeoff import epsilon_sweep, nondominated
from railopt.design.variables import DesignVariable

__all__ = [
    "METHODS",
    "STATUSES",
    "CampaignStore",
    "DesignVariable",
    "Evaluation",
    "MinimaxProblem",
    "SolveResult",
    "Surface",
    "check_designs",
    "dask_client",
    "epsilon_sweep",
    "grid_map",
    "distinct_optima",
    "label_clusters",
    "map_unordered",
    "multistart",
    "nondominated",
    "objective_surface",
    "solve",
    "start_points",
]

"""Study kind ``campaign``: a multi-start minimax campaign of any catalogued model, from config alone.

A config lists the models (``[[models]]``: a label, a registered model and its options), the
design variables (``[[design.variables]]``: name, bounds, scale), the objective (an output over a
band), optional constraints (other outputs' maxima below a limit), the matrix of methods ×
objectives (thesis approximation (4.71)–(4.73) and/or the certified band maximum), the starts
(Sobol/LHS plus named designs or explicit points) and the checks of every distinct optimum
(stability).  One campaign runs per model × objective × method, each into its own resumable
SQLite store.  Tables: ``comparison.csv`` (one row per campaign: success rate, distinct optima,
evaluations, wall time, best U, true band peak at the best design, comparison with named designs),
``starts.csv/.parquet``, ``optima.csv`` (distinct optima with their checks); figure ``frf.png``; with
``[report] before``, ``[[tradeoffs]]`` or ``[[surfaces]]`` the before/after, trade-off and surface sections.

Modules: :mod:`.config` (the config; the specs shared with other kinds are in :mod:`railopt.studies.specs`),
:mod:`.run` (compute, warnings), :mod:`.stores` (stores and resume), :mod:`.problems` (the minimax problems),
:mod:`.selection` (the recommended design), :mod:`.sections` (comparison, FRF panels, before/after, model
sections), :mod:`.tradeoffs` (ε-sweeps, surfaces), :mod:`.report` (tables, figures, summary).
"""

from railopt.studies.kind import StudyKind, register_kind
from railopt.studies.kinds.campaign.config import CampaignStudyConfig
from railopt.studies.kinds.campaign.problems import campaign_problem, design_peak
from railopt.studies.kinds.campaign.report import report
from railopt.studies.kinds.campaign.run import compute, warnings

__all__ = ["KIND", "CampaignStudyConfig", "campaign_problem", "compute", "design_peak", "report"]

SUMMARY = "multi-start minimax campaign (problems × methods × objectives) of a catalogued model"
KIND = register_kind(StudyKind("campaign", CampaignStudyConfig, compute, report, summary=SUMMARY, warnings=warnings))

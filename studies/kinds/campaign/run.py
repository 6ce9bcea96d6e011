"""Compute of the ``campaign`` kind: the campaigns (models × objectives × methods) into their resumable stores,
the checks of every distinct optimum, the comparison with named designs, and the data of the report's
sections (FRFs at the optima, before/after, stability, root loci, trade-offs, surfaces).  Writes no file
but the campaign stores.

The pieces: :mod:`.stores` (stores and resume), :mod:`.problems` (the minimax problems), :mod:`.selection`
(the recommended design), :mod:`.sections` (comparison rows, FRF panels, before/after, model sections)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from railopt.design.parallel import reporting_progress
from railopt.studies.kind import StudyContext, dask_context
from railopt.studies.kinds.campaign.config import CampaignStudyConfig, model_tag
from railopt.studies.kinds.campaign.problems import _p, campaign_label
from railopt.studies.kinds.campaign.sections import ModelSections, _comparison_row, _frf_panels, _model_sections, _short
from railopt.studies.kinds.campaign.selection import _recommend
from railopt.studies.kinds.campaign.stores import _campaign, check_stores
from railopt.studies.output.progress import Progress

__all__ = ["CampaignResult", "compute", "warnings"]


def warnings(cfg: CampaignStudyConfig) -> list[str]:
    """An existing design that fails a check (e.g. hunts below the required speed): the study still runs."""
    out = []
    for i, (label, setup) in enumerate(cfg.setups().items()):
        existing = setup.named_designs.get("existing")
        if existing is None:
            continue
        names = [n for n in existing if n in setup.family.parameters]
        p, _ = setup.parameters(names, np.array([existing[n] for n in names]))
        for name in cfg.design.checks:
            if getattr(setup.checks[name], "expensive", False):
                out.append(f"models[{i}] ({label}): the existing design's {name!r} check is not run before the "
                           "campaign (minutes per design); the run reports it")
                continue
            result = setup.checks[name](p)
            failed = [f for f, ok in result.flags.items() if not ok]
            if failed:
                numbers = ", ".join(f"{k} = {v:.4g}" for k, v in result.data.items())
                out.append(f"models[{i}] ({label}): the existing design fails the {name!r} check "
                           f"({', '.join(failed)} is false: value {result.value:.4g}; {numbers})")
    return out


# ---------------------------------------------------------------------------------------------- compute
@dataclass(frozen=True)
class CampaignResult:
    """Every campaign's starts and checked optima, the comparison, FRF panels and the report sections."""

    config: CampaignStudyConfig
    comparison: pd.DataFrame
    starts: pd.DataFrame
    optima: pd.DataFrame
    table: pd.DataFrame  # the CLI's short comparison
    frf_panels: list
    sections: list[ModelSections]
    named: dict[str, dict[str, float]] = field(default_factory=dict)  # model -> its existing design
    existing_checks: dict[str, dict[str, dict]] = field(default_factory=dict)  # model -> check -> payload


def compute(config: CampaignStudyConfig, context: StudyContext) -> CampaignResult:
    """Run every campaign of the study (stores, resume, checks of the optima), the trade-offs and
    surfaces, and select the recommended design: a :class:`CampaignResult`, data only (no files)."""
    cfg = config
    setups = cfg.setups()
    names = [v.name for v in cfg.design.variables]
    keys = [(m, prob, o, meth) for m in setups for prob in cfg.design.problems for o, meth in cfg.design.plan(prob)]
    check_stores(context, [campaign_label(m, o, meth, prob) for m, prob, o, meth in keys])
    tables: dict[tuple[str, str, str, str], pd.DataFrame] = {}
    optima: dict[tuple[str, str, str, str], pd.DataFrame] = {}
    rows = []
    flags: dict[tuple[str, str, str, str], list[str]] = {}
    if context.workers != 0 and "nonlinear_hunting" in cfg.design.checks:  # its checks run on the workers
        from railopt.studies.kernel_warmup import warm_nonlinear_kernels

        warm_nonlinear_kernels(context.show_progress)
    with dask_context(context) as client:
        for key in keys:
            tables[key], optima[key], flags[key] = _campaign(cfg, setups[key[0]], key, context, client)
            rows.append(_comparison_row(cfg, setups[key[0]], key, tables[key], optima[key], flags[key]))
        comparison = pd.DataFrame(rows)
        recommended = {m: _recommend(cfg, s, m, optima, flags, cfg.design.problems[0]) for m, s in setups.items()}
        sections = []
        if cfg.report.before or cfg.tradeoffs or cfg.surfaces or any(recommended.values()):
            for m, s in setups.items():  # trade-off sweeps and surfaces: many maps, one progress line for them all
                bar = Progress(f"{m}: trade-offs, surfaces and checks", unit="task", enabled=context.show_progress)
                with reporting_progress(bar.over_maps()):
                    sections.append(_model_sections(cfg, m, s, comparison, tables,
                                                    model_tag(m, len(setups)), client, recommended[m]))
                bar.close()
    starts = pd.concat([t.drop(columns=["functions"], errors="ignore").assign(model=m, problem=prob, objective=o,
                                                                             method=meth)
                        for (m, prob, o, meth), t in tables.items()], ignore_index=True)
    optima_table = pd.concat([t.assign(model=m, problem=prob, objective=o, method=meth)
                              for (m, prob, o, meth), t in optima.items()], ignore_index=True)
    named = {m: {n: float(s.named_designs["existing"][n]) for n in names} for m, s in setups.items()
             if "existing" in s.named_designs}
    existing_checks = {m: {c: s.checks[c](_p(cfg, s, named[m])).payload() for c in cfg.design.checks}
                       for m, s in setups.items() if m in named}
    return CampaignResult(cfg, comparison, starts, optima_table, _short(comparison, names),
                          _frf_panels(cfg, setups, comparison), sections, named, existing_checks)

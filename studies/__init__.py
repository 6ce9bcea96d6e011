"""railopt.studies: study kinds driven by TOML, the model catalog, the model → design adapter, the CLI.

From Python, :func:`run_study` runs a study TOML as ``railopt run`` does and returns its tables as DataFrames.
"""

from railopt.studies.run_study import StudyRun, run_study

__all__: list[str] = ["StudyRun", "run_study"]

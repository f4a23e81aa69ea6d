"""redmax from Python (docs/python.md): batch studies on Dask (redmax.batch, module redmax.study)."""
from .study import BatchResult, StudyError, batch, load_study  # noqa: F401  (stdlib + Dask only)

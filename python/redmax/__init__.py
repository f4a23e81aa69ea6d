"""redmax from Python (docs/python.md): batch studies on Dask (redmax.batch)."""
from . import batch as _batch_module  # noqa: F401  (stdlib + Dask only)
from .batch import BatchResult, StudyError

batch = _batch_module.batch

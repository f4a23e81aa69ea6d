"""redmax from Python (docs/python.md).

    import redmax
    m = redmax.Model("M.osim")                    # m.summary, m.description: dicts from the converter
    r = redmax.inverse_dynamics(m, coordinates="Q.mot", external_loads="L.xml", lowpass=6,
                                t0=0.4, t1=1.6, muscle_mass="physiological")
    r.labels, r.time, r.values                    # list, NumPy (rows), NumPy (rows x columns)
    r.to_pandas()                                 # where python3-pandas is installed
    redmax.batch("STUDY.json", "out/")            # a study on a local Dask cluster

The compiled half (redmax._core, pybind11) calls the library entry points `redmax id`, `redmax
lengths` and `redmax convert` use. Errors raise redmax.ConvertError (bad input; the message is the
CLI's "FILE[:LINE]: what") or redmax.Error; long calls release the GIL. redmax.batch needs only
the standard library and Dask (python3-distributed), so it works without the compiled module.
"""
import json as _json
import os as _os

from .study import BatchResult, StudyError, batch, load_study  # noqa: F401

try:
    from . import _core
    ConvertError, Error = _core.ConvertError, _core.Error
except ImportError as _e:  # built without pybind11: only redmax.batch
    _core = None
    _core_missing = str(_e)

    class Error(RuntimeError):
        pass

    class ConvertError(ValueError):
        pass


def _need_core():
    if _core is None:
        raise ImportError("redmax._core is not built (needs pybind11-dev and python3-dev): " + _core_missing)
    return _core


class Table:
    """Columns with labels over time, as OpenSim's .sto/.mot: `labels` (list), `time` (rows,),
    `values` (rows x len(labels)), both NumPy float64."""

    def __init__(self, name, labels, time, values, in_degrees=False):
        self.name, self.labels, self.time, self.values, self.in_degrees = name, list(labels), time, values, in_degrees

    def __getitem__(self, label):
        """one column by label (a NumPy view of `values`)"""
        return self.values[:, self.labels.index(label)]

    def __repr__(self):
        return f"<redmax.Table '{self.name}': {len(self.time)} rows x {len(self.labels)} columns>"

    def to_pandas(self):
        """a pandas.DataFrame indexed by time (needs python3-pandas)"""
        import pandas
        return pandas.DataFrame(self.values, columns=self.labels, index=pandas.Index(self.time, name="time"))

    def write(self, path, full_precision=False):
        """write an OpenSim .sto/.mot (%16.8lf as OpenSim, or %.16e with full_precision), atomically"""
        import numpy
        _need_core().write_storage(_os.fspath(path), self.name, self.labels, numpy.asarray(self.time, float),
                                   numpy.asarray(self.values, float), bool(self.in_degrees), full_precision)


def read_storage(path):
    """read an OpenSim .sto/.mot into a Table (values as in the file: degrees stay degrees)"""
    return Table(*_need_core().read_storage(_os.fspath(path)))


class Model:
    """An OpenSim model as redmax's converter reads it (`redmax convert`): `summary` (dict of counts
    and the printed text) and `description` (dict, the intermediate description of `--json`)."""

    def __init__(self, path):
        self.path = _os.fspath(path)
        self._m = _need_core().load_model(self.path)
        self.description = _json.loads(self._m.description_json())
        d = self.description
        self.summary = {
            "name": d.get("name"), "osim_version": d.get("osim_version"),
            "bodies": len(d.get("bodies", [])), "total_mass": sum(b.get("mass", 0.0) for b in d.get("bodies", [])),
            "coordinates": len(d.get("coordinates", [])), "joints": len(d.get("joints", [])),
            "muscles": len(d.get("muscles", [])), "constraints": len(d.get("constraints", [])),
            "unsupported": len(d.get("unsupported", [])), "text": self._m.summary_text(),
        }

    def __repr__(self):
        return f"<redmax.Model '{self.summary['name']}' ({self.path})>"


def _model_path(model):
    return model.path if isinstance(model, Model) else _os.fspath(model)


def _flags(**kw):
    """keywords as `redmax` flags: lowpass=6 -> --lowpass 6, exact=True -> --exact, None left out"""
    out = []
    for k, v in kw.items():
        if v is None or v is False:
            continue
        flag = "--" + k.replace("_", "-")
        if v is True:
            out.append(flag)
        else:
            out += [flag, _os.fspath(v) if isinstance(v, _os.PathLike) else (repr(v) if isinstance(v, float) else str(v))]
    return out


def inverse_dynamics(model=None, coordinates=None, **flags):
    """`redmax id` (engine core): OpenSim's InverseDynamicsTool on a trial. Keywords are the CLI's
    flags with underscores (docs/commands.md: external_loads, lowpass, t0, t1, setup, exact,
    forces_to_exclude, muscle_mass, muscles, mass_points, specific_tension, muscle_density,
    transfer_body, transfer_fraction, wrap, ...), parsed by the CLI's own declarations, so defaults
    and checks are the command line's. Returns a Table of <coord>_moment / <coord>_force columns."""
    args = _flags(model=None if model is None else _model_path(model), coordinates=coordinates, **flags)
    return Table(*_need_core().inverse_dynamics(args))


def path_lengths(model, coordinates, wrap="exact"):
    """`redmax lengths`: every muscle's musculotendon length (m) at every frame of `coordinates`"""
    return Table(*_need_core().path_lengths(_model_path(model), _os.fspath(coordinates), wrap))

"""redmax from Python (docs/python.md).

    import redmax
    m = redmax.Model("M.osim")                    # m.summary, m.description: dicts from the converter
    r = redmax.inverse_dynamics(m, coordinates="Q.mot", external_loads="L.xml", lowpass=6,
                                t0=0.4, t1=1.6, muscle_mass="physiological")
    r.labels, r.time, r.values                    # list, NumPy (rows), NumPy (rows x columns)
    r.to_pandas()                                 # where python3-pandas is installed
    tau = redmax.inverse_dynamics(m, q=Q, qdot=QD, qddot=QDD)      # arrays (frames x coordinates)
    pts = redmax.mass_points(m, Q, muscle_mass="physiological")    # per muscle, (frames x N x 3)
    f = redmax.forward(setup="arm26_Setup_Forward.xml")            # f.states, f.controls
    a = redmax.analyze(setup="arm26_Setup_StaticOptimization.xml") # a.activation, a.force
    v = redmax.validate(model=m, coordinates="Q.mot", report="out/") # v.passed, v.summary
    redmax.batch("STUDY.json", "out/")            # a study on a local Dask cluster

Keywords are the command line's flags with underscores for dashes (``external_loads`` is
``--external-loads``), parsed by the CLI's own flag declarations compiled into the module, so
defaults, checks and messages are the command line's. The compiled half (redmax._core, pybind11)
calls the library entry points the commands use. Errors raise redmax.ConvertError (bad input; a
ValueError whose message is the CLI's "FILE[:LINE]: what"), ValueError (a bad keyword value, the
CLI's message) or redmax.Error (a run that failed); long calls release the GIL. redmax.batch needs
only the standard library and Dask (python3-distributed), so it works without the compiled module.
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
        """A run that failed (the compiled module is missing, so nothing raises it)."""

    class ConvertError(ValueError):
        """Bad input (the compiled module is missing, so nothing raises it)."""


def _need_core():
    if _core is None:
        raise ImportError("redmax._core is not built (needs pybind11-dev and python3-dev): " + _core_missing)
    return _core


class Table:
    """Columns with labels over time, as OpenSim's .sto/.mot: `labels` (list), `time` (rows,),
    `values` (rows x len(labels)), both NumPy float64. Tables the library computed own their
    memory and are handed over without a copy (`values` is then Fortran-ordered)."""

    def __init__(self, name, labels, time, values, in_degrees=False):
        self.name, self.labels, self.time, self.values, self.in_degrees = name, list(labels), time, values, in_degrees

    def __getitem__(self, label):
        """One column by label (a NumPy view of `values`)."""
        return self.values[:, self.labels.index(label)]

    def __len__(self):
        return len(self.time)

    def __repr__(self):
        return f"<redmax.Table '{self.name}': {len(self.time)} rows x {len(self.labels)} columns>"

    def to_pandas(self):
        """A pandas.DataFrame indexed by time (needs python3-pandas)."""
        import pandas
        return pandas.DataFrame(self.values, columns=self.labels, index=pandas.Index(self.time, name="time"))

    def write(self, path, full_precision=False, decimals=None, scientific=False, description=""):
        """Write an OpenSim .sto/.mot atomically: OpenSim's %16.8lf, %.16e with full_precision (the
        commands' --full-precision), or `decimals` digits (%.{decimals}f, or %.{decimals}e with
        scientific) as `redmax forward` and `analyze` write theirs. `description`: header lines."""
        import numpy
        _need_core().write_storage(_os.fspath(path), self.name, self.labels, numpy.asarray(self.time, float),
                                   numpy.asarray(self.values, float), bool(self.in_degrees), bool(full_precision),
                                   -1 if decimals is None else int(decimals), bool(scientific), description)


def read_storage(path):
    """Read an OpenSim .sto/.mot into a Table (values as in the file: degrees stay degrees)."""
    return Table(*_need_core().read_storage(_os.fspath(path)))


class Model:
    """An OpenSim model as redmax's converter reads it (`redmax convert`): `summary` (dict of counts
    and the printed text) and `description` (dict, the intermediate description of `--json`).
    Functions that take a model accept a Model or the .osim path."""

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


def _value(v):
    if isinstance(v, _os.PathLike):
        return _os.fspath(v)
    if isinstance(v, float):
        return repr(v)  # the shortest text that reads back as the same double
    return str(v)


_REPEATED = {"reference", "published"}  # flags given once per file; other lists are V1,V2,...


def _flags(**kw):
    """Keywords as `redmax` flags: lowpass=6 -> --lowpass 6, exact=True -> --exact, None and False
    left out, a list or tuple -> "V1,V2,..." (mass_sweep=[0, 0.5]), or the flag once per item for
    validate's reference and published."""
    out = []
    for k, v in kw.items():
        if v is None or v is False:
            continue
        flag = "--" + k.replace("_", "-")
        if v is True:
            out.append(flag)
        elif isinstance(v, (list, tuple)) and k in _REPEATED:
            for x in v:
                out += [flag, _value(x)]
        elif isinstance(v, (list, tuple)):
            out += [flag, ",".join(_value(x) for x in v)]
        else:
            out += [flag, _value(v)]
    return out


def inverse_dynamics(model=None, coordinates=None, *, q=None, qdot=None, qddot=None, time=None, loads=None,
                     with_inputs=False, **flags):
    """Inverse dynamics with the core engine, as `redmax id` computes it. Returns a Table of
    <coord>_moment / <coord>_force columns (N m or N), in the model's q order.

    A trial: `coordinates` (a .mot/.sto) and the CLI's other flags as keywords (docs/commands.md:
    external_loads, lowpass, t0, t1, setup, exact, forces_to_exclude, and the MUSCLE-MASS OPTIONS
    muscle_mass, muscles, mass_points, mass_region, specific_tension, muscle_density,
    transfer_body, transfer_fraction, wrap, wrap_width, wrap_network). The values equal
    `redmax id --full-precision`'s to the last digit. with_inputs=True also sets `r.inputs`, a dict
    of what the tool gave the engine per output frame: q, qdot, qddot (frames x coordinates) and
    loads (a list of dicts body, force, point, torque: frames x 3 in ground, or None).

    Arrays: q, qdot, qddot (frames x coordinates, the model's q order: the labels' order; radians,
    m) and `time` (frames; default 0, 1, ...), with `loads` in the form of `r.inputs["loads"]`
    (a point None means the body's origin), and the keywords model, exact and the MUSCLE-MASS
    OPTIONS (top:K ranks over the rows of q). qdot and qddot are the speeds the engine takes:
    dq/dt, except for Ball/Free/Ellipsoid joints without `exact`, where they are OpenSim's u (the
    rates read as angular velocity), as in the trial. The same q, qdot, qddot and loads as a
    trial's inputs give the trial's values bit for bit."""
    core = _need_core()
    mpath = None if model is None else _model_path(model)
    if q is not None or qdot is not None or qddot is not None:
        import numpy
        if coordinates is not None:
            raise ValueError("give coordinates (a trial) or q, qdot, qddot (arrays), not both")
        if q is None or qdot is None or qddot is None:
            raise ValueError("arrays need q, qdot and qddot")
        q, qdot, qddot = (numpy.ascontiguousarray(x, dtype=float) for x in (q, qdot, qddot))
        time = numpy.arange(len(q), dtype=float) if time is None else numpy.ascontiguousarray(time, dtype=float)
        load_list = []
        for ld in loads or []:
            load_list.append({k: (None if ld.get(k) is None else numpy.ascontiguousarray(ld[k], dtype=float))
                              if k != "body" else ld["body"] for k in ("body", "force", "point", "torque")})
        return Table(*core.inverse_dynamics_arrays(_flags(model=mpath, **flags), time, q, qdot, qddot, load_list))
    if loads is not None or time is not None:
        raise ValueError("loads and time go with arrays (q, qdot, qddot); a trial takes external_loads")
    table, inputs = core.inverse_dynamics(_flags(model=mpath, coordinates=coordinates, **flags), bool(with_inputs))
    r = Table(*table)
    if with_inputs:
        r.inputs = inputs
    return r


class MassPoints:
    """One muscle's mass points (`redmax.mass_points`): `name`, `path_type` ("I", "II", "III"),
    `alpha` (N, the arc-length fractions along the path), `mass` (N, kg), `points` (frames x N x 3,
    world positions in m) and `path` (one array per frame: the active path points, P x 3)."""

    def __init__(self, d):
        import numpy
        self.name, self.path_type = d["name"], d["path_type"]
        self.alpha, self.mass = numpy.asarray(d["alpha"]), numpy.asarray(d["mass"])
        self.points, self.path = d["points"], d["path"]

    def __repr__(self):
        return f"<redmax.MassPoints '{self.name}' (Type {self.path_type}): {len(self.alpha)} points, {self.mass.sum():.6g} kg>"


def mass_points(model, q, **flags):
    """The world positions of every muscle's mass points at the rows of q (frames x coordinates in
    the model's q order, or one row), with the MUSCLE-MASS OPTIONS as keywords (muscle_mass is
    needed: without it no muscle carries points). The model is built as `redmax id` builds it
    (mass taken from the bones); wrapping muscles follow their wrap model (wrap=smooth by default).
    Returns a dict muscle name -> MassPoints, in the model's muscle order."""
    import numpy
    q = numpy.ascontiguousarray(q, dtype=float)
    if q.ndim == 1:
        q = q[None, :]
    out = {}
    for d in _need_core().mass_points(_flags(model=_model_path(model), **flags), q):
        out[d["name"]] = MassPoints(d)
    return out


def path_lengths(model, coordinates, wrap="exact"):
    """`redmax lengths`: every muscle's musculotendon length (m) at every frame of `coordinates`,
    wrapping as OpenSim does (wrap="exact") or straight segments (wrap="none"). Returns a Table."""
    return Table(*_need_core().path_lengths(_model_path(model), _os.fspath(coordinates), wrap))


class ForwardResult:
    """What `redmax.forward` returns: `states` and `controls` (Tables, the columns `redmax forward`
    writes), `name`, integrator statistics `steps`, `rhs_evals`, `failed_steps`, `wall_s`,
    `warnings` (what the CLI prints as warnings), `files` (written only with out_dir) and
    `decimals`, the digits the files carry (%.{decimals}e: `states.write(p, decimals=f.decimals,
    scientific=True)` prints the CLI's numbers)."""

    def __init__(self, d):
        self.states, self.controls = Table(*d.pop("states")), Table(*d.pop("controls"))
        self.__dict__.update(d)

    def __repr__(self):
        return f"<redmax.ForwardResult '{self.name}': {len(self.states)} rows, {self.steps} steps>"


def forward(setup=None, **flags):
    """`redmax forward`: OpenSim's ForwardTool on a setup file (docs/forward.md). Keywords are the
    command's flags: setup, out_dir, muscle_class, integrator, report_interval, tolerance and the
    MUSCLE-MASS OPTIONS. The files are written (as the CLI writes them) only when out_dir is given.
    Returns a ForwardResult; a run that diverges raises redmax.Error naming the time."""
    return ForwardResult(_need_core().forward(_flags(setup=setup, **flags)))


class AnalyzeResult:
    """What `redmax.analyze` returns: `activation` and `force` (Tables: time x actuators, OpenSim's
    force-set order, rows of failed frames nan), per frame `iterations`, `constraint_violation`
    (max |A x - b|), `converged`, `status`; `failed` (frames that did not converge), `muscle_mass`
    (kg), `warnings`, `unsupported_analyses`, `is_muscle`, `files` (written only with out_dir),
    `decimals` (the setup's output_precision: the files' %.{decimals}f)."""

    def __init__(self, d):
        name, labels, time = d["name"], d["labels"], d["time"]
        self.activation = Table(name + "_activation", labels, time, d.pop("activation"))
        self.force = Table(name + "_force", labels, time, d.pop("force"))
        self.__dict__.update(d)

    def __repr__(self):
        return f"<redmax.AnalyzeResult '{self.name}': {len(self.time)} frames ({self.failed} failed), {len(self.labels)} actuators>"


def analyze(setup=None, **flags):
    """`redmax analyze`: OpenSim's AnalyzeTool with its StaticOptimization (docs/analyze.md).
    Keywords are the command's flags: setup, out_dir, muscle_class and the MUSCLE-MASS OPTIONS.
    The files (OpenSim's names and headers) are written only when out_dir is given. Frames that
    do not converge are kept (converged False, nan rows), as the CLI keeps them."""
    return AnalyzeResult(_need_core().analyze(_flags(setup=setup, **flags)))


class ValidationResult:
    """What `redmax.validate` returns: `passed`, `text` (the summary `redmax validate` prints),
    `report` (the folder), `summary` (its summary.json as a dict), `warnings`, `files`, `plots`."""

    def __init__(self, d):
        self.__dict__.update(d)
        with open(_os.path.join(self.report, "summary.json")) as fh:
            self.summary = _json.load(fh)

    def __repr__(self):
        return f"<redmax.ValidationResult {'PASS' if self.passed else 'FAIL'}: {self.report}>"


def validate(model=None, coordinates=None, report=None, **flags):
    """`redmax validate`: the trial solved by the core and by Simbody, compared with each other and
    with `reference` / `published` results (lists of files allowed), written as a report folder
    (`report`, required). Keywords are the command's flags (docs/commands.md: the inputs of
    inverse_dynamics, tolerance, max_tolerance, engine_tolerance, interpolation, no_simbody,
    mass_sweep, sweep_columns, no_plots, gnuplot). Returns a ValidationResult; a failed
    comparison is `passed == False`, not an exception."""
    mpath = None if model is None else _model_path(model)
    return ValidationResult(_need_core().validate(_flags(model=mpath, coordinates=coordinates, report=report,
                                                         **flags)))

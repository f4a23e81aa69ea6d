#!/usr/bin/python3
"""Batch studies on Dask: ``redmax batch STUDY.json [--scheduler ADDRESS] [--workers N] --out DIR``.

A study (docs/python.md §3) is JSON::

    {"trials": [{"name": "E", "command": "id", "args": ["--model", "M.osim", "--coordinates", "Q.mot"]}],
     "grid": {"--muscle-mass": ["none", "physiological"], "--mass-points": ["10", "20"]}}

Each trial is any redmax command with its arguments (relative paths resolved against the study
file's folder); the grid's flags are crossed and appended; the batch adds the command's output flag
(``--out-dir``, ``--out`` or ``--report``, read from the command's ``--help``) pointing into
``DIR/<trial>/<cell>/``. Each (trial, cell) is one task, run as a ``redmax`` subprocess on a Dask
worker. ``DIR/results.csv`` has one row per cell, in study order.

Outputs are atomic: a task writes into ``DIR/<trial>/.<cell>.tmp-<id>/`` and renames it to
``DIR/<trial>/<cell>/`` once the command succeeded, with ``cell.json`` (the row) inside; a rerun skips
cells whose folder holds ``cell.json``. A failed cell leaves no folder, so a rerun retries it.

Only the standard library and Dask (Debian python3-distributed) are needed; this file runs as a
script (what ``redmax batch`` execs) or as ``redmax.study`` in Python (``redmax.batch`` is its ``batch``).
"""
import argparse
import csv
import io
import itertools
import json
import os
import re
import shutil
import subprocess
import sys
import time
import uuid

try:
    from . import report as _report
except ImportError:  # run as a script (what `redmax batch` execs): report.py sits beside it
    import report as _report

RESULTS = "results.csv"
CELL_FILE = "cell.json"
BASE_COLUMNS = ["trial", "cell"]
TAIL_COLUMNS = ["status", "error", "wall_s", "output"]
RESERVED = (RESULTS, "results.parquet", _report.REPORT, _report.FIGURE_DIR)  # DIR's own entries


class StudyError(ValueError):
    """A study file that does not follow the contract (exit code 2)."""


# --- the study -------------------------------------------------------------------------------

def find_redmax():
    """The redmax executable: $REDMAX_EXE, else the build a `pip install` recorded, else
    build/cli/redmax beside this source tree, else PATH."""
    env = os.environ.get("REDMAX_EXE")
    if env:
        return env
    try:
        from ._build_info import REDMAX_EXE as recorded
        if os.access(recorded, os.X_OK):
            return recorded
    except ImportError:
        pass
    here = os.path.dirname(os.path.abspath(__file__))
    for cand in (os.path.join(here, "..", "..", "build", "cli", "redmax"),
                 os.path.join(here, "..", "..", "cli", "redmax")):
        if os.access(cand, os.X_OK):
            return os.path.abspath(cand)
    found = shutil.which("redmax")
    if not found:
        raise StudyError("cannot find the redmax executable (set REDMAX_EXE)")
    return found


def _resolve(arg, base):
    """A relative path that exists beside the study file becomes absolute; anything else is kept."""
    if not arg or arg.startswith("-") or os.path.isabs(arg):
        return arg
    cand = os.path.join(base, arg)
    return os.path.abspath(cand) if os.path.exists(cand) else arg


def _cell_name(flags, values):
    if not flags:
        return "default"
    parts = []
    for f, v in zip(flags, values):
        parts.append(f.lstrip("-") + "=" + re.sub(r"[^A-Za-z0-9._+-]", "_", str(v)))
    return ",".join(parts)


def load_study(path):
    """Reads STUDY.json; returns (trials, grid flags, cells) with cells in study order."""
    try:
        with open(path) as fh:
            study = json.load(fh)
    except OSError as e:
        raise StudyError(f"{path}: {e.strerror}")
    except json.JSONDecodeError as e:
        raise StudyError(f"{path}:{e.lineno}: {e.msg}")
    if not isinstance(study, dict) or not isinstance(study.get("trials"), list) or not study["trials"]:
        raise StudyError(f"{path}: a study needs a non-empty \"trials\" list")
    grid = study.get("grid", {}) or {}
    if not isinstance(grid, dict) or any(not isinstance(v, list) or not v for v in grid.values()):
        raise StudyError(f"{path}: \"grid\" maps each flag to a non-empty list of values")
    base = os.path.dirname(os.path.abspath(path))
    flags = list(grid.keys())
    trials, names = [], set()
    for i, t in enumerate(study["trials"]):
        if not isinstance(t, dict) or not isinstance(t.get("name"), str) or not isinstance(t.get("command"), str):
            raise StudyError(f"{path}: trial {i + 1} needs a \"name\" and a \"command\"")
        name = t["name"]
        if not re.fullmatch(r"[A-Za-z0-9._+-]+", name) or name in names:
            raise StudyError(f"{path}: trial name '{name}' must be unique and a plain file name")
        if name in RESERVED or name.startswith("."):
            raise StudyError(f"{path}: trial name '{name}' is taken by the study's own files ({', '.join(RESERVED)})")
        names.add(name)
        args = t.get("args", [])
        if not isinstance(args, list):
            raise StudyError(f"{path}: trial '{name}': \"args\" is a list of strings")
        trials.append({"name": name, "command": t["command"], "args": [_resolve(str(a), base) for a in args]})
    cells = []
    for t in trials:
        for values in itertools.product(*(grid[f] for f in flags)):
            values = [str(v) for v in values]
            extra = []
            for f, v in zip(flags, values):
                extra += [f, _resolve(v, base)]
            cells.append({"trial": t["name"], "command": t["command"], "cell": _cell_name(flags, values),
                          "args": t["args"] + extra, "grid": dict(zip(flags, values))})
    return trials, flags, cells


# the option's own line: "--out" then a space or the line's end (not "--output-dt"), and its type name
_HELP_OPTION = re.compile(r"^\s*(--out-dir|--out|--report)(?=\s|$)(?:[ \t]+([A-Za-z0-9_.|]+))?", re.M)


def output_flag(redmax, command):
    """(flag, file name or None for a folder) of `command`, read from its --help."""
    try:
        text = subprocess.run([redmax, command, "--help"], capture_output=True, text=True, timeout=60).stdout
    except (OSError, subprocess.TimeoutExpired):
        return None
    found = {}
    for m in _HELP_OPTION.finditer(text):
        found.setdefault(m.group(1), m.group(2) or "")
    for flag in ("--out-dir", "--out", "--report"):
        if flag in found:
            kind = found[flag]
            if flag != "--out" or kind in ("", "DIR"):
                return flag, None
            return flag, kind.lower()  # OUT.sto -> out.sto, STATES.sto -> states.sto
    return None


# --- one task --------------------------------------------------------------------------------

_FIGURE = re.compile(r"(-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)\s+([A-Za-z][A-Za-z_]*)")


def summary_figures(stdout):
    """`N word` pairs of the command's last stdout line, but not those that depend on the clock."""
    lines = [l for l in stdout.splitlines() if l.strip()]
    if not lines:
        return {}
    line = lines[-1]
    figures = {}
    for m in _FIGURE.finditer(line):
        value, word = m.group(1), m.group(2)
        rest = line[m.end():m.end() + 6]
        if word in ("s", "wall") or rest.startswith("/s") or word in figures:
            continue
        figures[word] = value
    return figures


def _error_message(stderr, rc):
    errs = [l for l in stderr.splitlines() if l.startswith("error:")]
    if errs:
        return errs[0][len("error:"):].strip()
    lines = [l for l in stderr.splitlines() if l.strip()]
    return (lines[-1].strip() if lines else "") + f" (exit code {rc})"


def run_cell(redmax, out_dir, cell, out_spec):
    """Runs one cell (a Dask task); returns its row. Idempotent: a complete cell is not rerun."""
    trial_dir = os.path.join(out_dir, cell["trial"])
    final = os.path.join(trial_dir, cell["cell"])
    done = os.path.join(final, CELL_FILE)
    if os.path.exists(done):
        with open(done) as fh:
            row = json.load(fh)
        row["skipped"] = True
        return row
    os.makedirs(trial_dir, exist_ok=True)
    tmp = os.path.join(trial_dir, f".{cell['cell']}.tmp-{uuid.uuid4().hex[:12]}")
    os.makedirs(tmp)
    args = [redmax, cell["command"]] + cell["args"]
    out_rel = os.path.join(cell["trial"], cell["cell"])
    if out_spec is not None:
        flag, name = out_spec
        args += [flag, tmp if name is None else os.path.join(tmp, name)]
        if name is not None:
            out_rel = os.path.join(out_rel, name)
    start = time.perf_counter()
    try:
        p = subprocess.run(args, capture_output=True, text=True, cwd=tmp)
        rc, stdout, stderr = p.returncode, p.stdout, p.stderr
    except OSError as e:
        rc, stdout, stderr = 127, "", f"error: {e}"
    wall = time.perf_counter() - start
    row = {"trial": cell["trial"], "cell": cell["cell"], "grid": cell["grid"],
           "status": "ok" if rc == 0 else "error", "error": "" if rc == 0 else _error_message(stderr, rc),
           "wall_s": wall, "output": out_rel if rc == 0 else "", "figures": summary_figures(stdout) if rc == 0 else {}}
    if rc != 0:
        shutil.rmtree(tmp, ignore_errors=True)
        return row
    with open(os.path.join(tmp, "stdout.txt"), "w") as fh:
        fh.write(stdout)
    with open(os.path.join(tmp, CELL_FILE + ".part"), "w") as fh:
        json.dump(row, fh, sort_keys=True)
    os.replace(os.path.join(tmp, CELL_FILE + ".part"), os.path.join(tmp, CELL_FILE))
    try:
        os.rename(tmp, final)  # atomic; the folder appears complete or not at all
    except OSError:
        # another attempt of the same task (a worker declared dead while its process ran on) won
        shutil.rmtree(tmp, ignore_errors=True)
        if not os.path.exists(done):
            raise
        with open(done) as fh:
            row = json.load(fh)
    return row


# --- the table -------------------------------------------------------------------------------

def _fmt_wall(x):
    return f"{x:.6f}"


def results_table(rows, flags):
    """CSV text: trial, cell, each grid flag, status, error, wall_s, output, then summary figures."""
    fig_cols = []
    for r in rows:
        for k in r.get("figures", {}):
            if k not in fig_cols:
                fig_cols.append(k)
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow(BASE_COLUMNS + flags + TAIL_COLUMNS + fig_cols)
    for r in rows:
        w.writerow([r["trial"], r["cell"]] + [r["grid"].get(f, "") for f in flags] +
                   [r["status"], r["error"], _fmt_wall(r["wall_s"]), r["output"]] +
                   [r.get("figures", {}).get(k, "") for k in fig_cols])
    return out.getvalue()


def _write_atomic(path, text):
    tmp = f"{path}.tmp-{os.getpid()}"
    with open(tmp, "w") as fh:
        fh.write(text)
    os.replace(tmp, path)


def _clean_stale(out_dir):
    # temporaries an interrupted run left behind
    if not os.path.isdir(out_dir):
        return
    for trial in os.listdir(out_dir):
        d = os.path.join(out_dir, trial)
        if os.path.isdir(d):
            for x in os.listdir(d):
                if x.startswith(".") and ".tmp-" in x:
                    shutil.rmtree(os.path.join(d, x), ignore_errors=True)


# --- the study on Dask -----------------------------------------------------------------------

class BatchResult:
    """What `batch` returns: `rows` (dicts, study order: trial, cell, grid, status, error, wall_s,
    output, figures), the grid `flags`, the paths `csv_path`, `parquet_path` (None without
    python3-pyarrow), `report_path` and `figures` (the report's SVGs)."""

    def __init__(self, rows, flags, csv_path, parquet_path=None, report_path=None, figures=()):
        self.rows, self.flags, self.csv_path = rows, flags, csv_path
        self.parquet_path, self.report_path, self.figures = parquet_path, report_path, list(figures)

    @property
    def errors(self):
        """The number of cells whose status is not ok."""
        return sum(r["status"] != "ok" for r in self.rows)

    def to_pandas(self):
        """results.csv as a pandas.DataFrame of strings (needs python3-pandas)."""
        import pandas
        return pandas.read_csv(self.csv_path, dtype=str, keep_default_na=False)


def _progress(stream, done, total, errors, skipped, start):
    if stream is None:
        return
    el = time.perf_counter() - start
    stream.write(f"batch: {done}/{total} cells ({errors} errors, {skipped} skipped), {el:.1f} s\n")
    stream.flush()


def batch(study, out, scheduler=None, workers=None, client=None, serial=False, redmax=None,
          progress=sys.stderr):
    """Runs STUDY.json into folder `out`; returns a BatchResult (exit code 1 when `.errors`).

    scheduler: address of an existing Dask scheduler; otherwise a local cluster of `workers`
    processes (default: this machine's cores), or `client`, an existing distributed.Client.
    serial=True runs the cells one after another in this process (no Dask), the reference the tests
    compare Dask runs with."""
    redmax = redmax or find_redmax()
    _, flags, cells = load_study(study)
    out = os.path.abspath(out)
    os.makedirs(out, exist_ok=True)
    _clean_stale(out)
    specs = {}
    for c in cells:
        if c["command"] not in specs:
            specs[c["command"]] = output_flag(redmax, c["command"])
    start = time.perf_counter()
    rows = [None] * len(cells)
    done = errors = skipped = 0

    def record(i, row):
        nonlocal done, errors, skipped
        rows[i] = row
        done += 1
        errors += row["status"] != "ok"
        skipped += bool(row.pop("skipped", False))
        _progress(progress, done, len(cells), errors, skipped, start)

    if serial:
        for i, c in enumerate(cells):
            record(i, run_cell(redmax, out, c, specs[c["command"]]))
    else:
        from distributed import Client, LocalCluster, as_completed
        own = []
        if client is None:
            if scheduler:
                client = Client(scheduler)
            else:
                # workers import this module by name: make it importable in their processes
                pkg_parent = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
                os.environ["PYTHONPATH"] = os.pathsep.join(
                    [pkg_parent] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])
                cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1,
                                       processes=True, dashboard_address=None)
                client = Client(cluster)
                own += [client, cluster]
            if scheduler:
                own.append(client)
        try:
            futures = {}
            for i, c in enumerate(cells):
                f = client.submit(run_cell, redmax, out, c, specs[c["command"]], pure=False,
                                  key=f"redmax-cell-{i}-{uuid.uuid4().hex[:8]}")
                futures[f] = i
            for f in as_completed(futures):
                i = futures[f]
                try:
                    row = f.result()
                except Exception as e:  # the task itself failed (e.g. killed too often)
                    c = cells[i]
                    row = {"trial": c["trial"], "cell": c["cell"], "grid": c["grid"], "status": "error",
                           "error": f"task failed: {e}", "wall_s": 0.0, "output": "", "figures": {}}
                record(i, row)
        finally:
            for x in own:
                x.close()
    csv_path = os.path.join(out, RESULTS)
    _write_atomic(csv_path, results_table(rows, flags))
    parquet_path = write_parquet(csv_path)
    el = time.perf_counter() - start
    figures = _report.write_report(out, rows, flags, elapsed_s=el)
    if progress is not None:
        progress.write(f"batch: {len(cells)} cells, {errors} errors, {skipped} skipped, {el:.2f} s wall"
                       f" -> {csv_path}, {os.path.join(out, _report.REPORT)}\n")
    return BatchResult(rows, flags, csv_path, parquet_path, os.path.join(out, _report.REPORT), figures)


def write_parquet(csv_path):
    """results.parquet beside results.csv (the same columns, as strings) where python3-pyarrow is
    installed, written atomically; returns its path, or None (and writes nothing) without pyarrow."""
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError:
        return None
    with open(csv_path, newline="") as fh:
        table = list(csv.reader(fh))
    header, body = table[0], table[1:]
    cols = {h: [r[i] for r in body] for i, h in enumerate(header)}
    path = csv_path[:-4] + ".parquet"
    pyarrow.parquet.write_table(pyarrow.table(cols), path + ".tmp")
    os.replace(path + ".tmp", path)
    return path


def main(argv=None):
    """`redmax batch`'s command line (what cli/cmd_batch.cpp execs); returns the exit code."""
    ap = argparse.ArgumentParser(prog="redmax batch", description="run a study on Dask")
    ap.add_argument("study", metavar="STUDY.json")
    ap.add_argument("--scheduler", metavar="ADDRESS")
    ap.add_argument("--workers", type=int, metavar="N")
    ap.add_argument("--out", required=True, metavar="DIR")
    ap.add_argument("--serial", action="store_true")
    a = ap.parse_args(argv)
    if a.workers is not None and a.workers < 1:
        print("error: --workers must be positive", file=sys.stderr)
        return 2
    try:
        r = batch(a.study, a.out, scheduler=a.scheduler, workers=a.workers, serial=a.serial)
    except StudyError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 1 if r.errors else 0


if __name__ == "__main__":
    sys.exit(main())

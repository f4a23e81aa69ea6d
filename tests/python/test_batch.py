"""redmax batch (python/redmax/study.py): the study contract, a bad trial, rerun-skip, and a worker
killed mid-study, each on a local Dask cluster (docs/python.md §3)."""
import csv
import json
import os
import shutil
import signal
import subprocess
import threading
import time

import pytest

from conftest import MODELS

import redmax.study as rb

LEG = "running_leg.osim"
SWING = "running_leg_swing.mot"


def make_study(tmp, trials, grid):
    """A study beside copies of the bundled running leg, with relative paths as users write them."""
    os.makedirs(os.path.join(tmp, "data"), exist_ok=True)
    for f in (LEG, SWING):
        shutil.copy(os.path.join(MODELS, f), os.path.join(tmp, "data", f))
    path = os.path.join(tmp, "study.json")
    with open(path, "w") as fh:
        json.dump({"trials": trials, "grid": grid}, fh)
    return path


def id_trial(name="leg"):
    return {"name": name, "command": "id", "args": ["--model", f"data/{LEG}", "--coordinates", f"data/{SWING}"]}


def read_table(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


def without_wall(rows):
    return [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]


def test_study_contract(tmp_path, redmax_exe):
    lengths = {"name": "len", "command": "lengths", "args": ["--model", f"data/{LEG}", "--coordinates", f"data/{SWING}"]}
    study = make_study(str(tmp_path), [id_trial(), lengths],
                       {"--muscle-mass": ["physiological"], "--mass-points": ["10", "20"]})
    # lengths takes no muscle mass: a usage error per cell, recorded, exit code 1
    out = tmp_path / "out"
    p = subprocess.run([redmax_exe, "batch", study, "--workers", "2", "--out", str(out)], capture_output=True, text=True)
    assert p.returncode == 1, p.stderr
    assert "batch: 4/4 cells" in p.stderr  # progress while it runs
    rows = read_table(out / "results.csv")
    assert list(rows[0].keys())[:8] == ["trial", "cell", "--muscle-mass", "--mass-points", "status", "error",
                                        "wall_s", "output"]
    assert [(r["trial"], r["--mass-points"]) for r in rows] == [("leg", "10"), ("leg", "20"), ("len", "10"), ("len", "20")]
    for r in rows[:2]:
        assert r["status"] == "ok" and r["error"] == ""
        assert r["output"] == f"leg/muscle-mass=physiological,mass-points={r['--mass-points']}/out.sto"
        assert (out / r["output"]).is_file()
        assert r["frames"] == "81" and r["coordinates"] == "11"  # the summary line's figures
        assert float(r["wall_s"]) > 0
    for r in rows[2:]:
        assert r["status"] == "error" and "--muscle-mass" in r["error"] and r["output"] == ""
        assert not (out / "len" / r["cell"]).exists()
    # the grid's flags were appended: 10 and 20 points give different moments
    a, b = ((out / r["output"]).read_text() for r in rows[:2])
    assert a != b
    # the same run, serial and by the command line's own --out: identical numbers
    ref = tmp_path / "ref.sto"
    subprocess.run([redmax_exe, "id", "--model", str(tmp_path / "data" / LEG), "--coordinates",
                    str(tmp_path / "data" / SWING), "--muscle-mass", "physiological", "--mass-points", "10",
                    "--out", str(ref)], check=True, capture_output=True)
    assert ref.read_text() == a


def test_bad_trial(tmp_path, redmax_exe):
    bad = {"name": "bad", "command": "id", "args": ["--model", "data/missing.osim", "--coordinates", f"data/{SWING}"]}
    study = make_study(str(tmp_path), [bad, id_trial()], {"--muscle-mass": ["none", "physiological"]})
    out = tmp_path / "out"
    p = subprocess.run([redmax_exe, "batch", study, "--workers", "2", "--out", str(out)], capture_output=True, text=True)
    assert p.returncode == 1
    rows = read_table(out / "results.csv")
    assert [r["status"] for r in rows] == ["error", "error", "ok", "ok"]
    assert all("missing.osim: no such file" in r["error"] for r in rows[:2])
    assert not (out / "bad").exists() or not any(x for x in os.listdir(out / "bad") if not x.startswith("."))
    # a malformed study is bad input: exit code 2
    (tmp_path / "broken.json").write_text('{"trials": ')
    p = subprocess.run([redmax_exe, "batch", str(tmp_path / "broken.json"), "--out", str(out)], capture_output=True, text=True)
    assert p.returncode == 2 and "broken.json:1" in p.stderr


def test_rerun_skips_complete_cells(tmp_path, redmax_exe):
    study = make_study(str(tmp_path), [id_trial()], {"--muscle-mass": ["physiological"], "--mass-points": ["5", "10", "20"]})
    out = str(tmp_path / "out")
    first = rb.batch(study, out, serial=True, progress=None)
    assert first.errors == 0
    files = {r["output"]: os.stat(os.path.join(out, r["output"])).st_mtime_ns for r in first.rows}
    # an interrupted run's leftovers: a half-written temporary folder, and one cell removed
    os.makedirs(os.path.join(out, "leg", ".muscle-mass=physiological,mass-points=5.tmp-dead"))
    shutil.rmtree(os.path.join(out, "leg", "muscle-mass=physiological,mass-points=10"))
    with open(os.path.join(out, "results.csv")) as fh:
        table_before = fh.read()
    import io
    log = io.StringIO()
    second = rb.batch(study, out, workers=1, progress=log)
    assert "3 cells, 0 errors, 2 skipped" in log.getvalue()
    for r in second.rows:
        m = os.stat(os.path.join(out, r["output"])).st_mtime_ns
        assert (m == files[r["output"]]) == ("points=10" not in r["output"])
    assert not [x for x in os.listdir(os.path.join(out, "leg")) if ".tmp-" in x]
    with open(os.path.join(out, "results.csv")) as fh:
        table_after = fh.read()
    assert without_wall(list(csv.DictReader(io.StringIO(table_before)))) == \
        without_wall(list(csv.DictReader(io.StringIO(table_after))))


def test_worker_killed_mid_study(tmp_path, redmax_exe):
    from distributed import Client, LocalCluster
    masses = ["0.1", "0.2", "0.3", "0.4", "0.5", "0.6", "0.7", "0.8"]
    study = make_study(str(tmp_path), [id_trial()],
                       {"--muscle-mass": ["transfer"], "--transfer-body": ["tibia_r"], "--transfer-fraction": masses,
                        "--mass-points": ["20", "40"]})
    serial = rb.batch(study, str(tmp_path / "serial"), serial=True, progress=None)
    assert serial.errors == 0
    killed = []
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        pids = client.run(os.getpid)

        def killer():
            # as soon as a cell is complete, kill a worker that is running one
            deadline = time.time() + 60
            while time.time() < deadline and not killed:
                busy = [a for a, keys in client.processing().items() if keys]
                leg = tmp_path / "dask" / "leg"
                if busy and leg.exists() and any((leg / d / "cell.json").exists() for d in os.listdir(leg)):
                    os.kill(pids[busy[0]], signal.SIGKILL)
                    killed.append(busy[0])
                time.sleep(0.01)

        t = threading.Thread(target=killer)
        t.start()
        dask = rb.batch(study, str(tmp_path / "dask"), client=client, progress=None)
        t.join()
    assert killed, "no worker was killed (the study ended first)"
    assert dask.errors == 0
    a, b = read_table(tmp_path / "serial" / "results.csv"), read_table(tmp_path / "dask" / "results.csv")
    assert without_wall(a) == without_wall(b)
    for r in a:  # every output bit for bit
        assert (tmp_path / "serial" / r["output"]).read_bytes() == (tmp_path / "dask" / r["output"]).read_bytes()


def test_summary_report_and_parquet(tmp_path, redmax_exe):
    from redmax import report
    sim = {"name": "pend", "command": "simulate",
           "args": ["--model", "data/double_pendulum_straight.osim", "--duration", "0.2"]}
    os.makedirs(tmp_path / "data")
    shutil.copy(os.path.join(MODELS, "double_pendulum_straight.osim"), tmp_path / "data")
    study = tmp_path / "study.json"
    study.write_text(json.dumps({"trials": [sim], "grid": {"--integrator": ["rk45", "euler"],
                                                         "--muscle-mass-kg": ["straight_muscle=0.5",
                                                                              "straight_muscle=1"]}}))
    out = tmp_path / "out"
    res = rb.batch(str(study), str(out), serial=True, progress=None)
    assert res.errors == 0
    rows = read_table(out / "results.csv")
    # --out STATES.sto read from simulate's --help (not its --output-dt)
    assert all(r["output"].endswith("/states.sto") and (out / r["output"]).is_file() for r in rows)
    # the simulate summary's figures: steps, rhs evaluations, failed steps, energy (J), drift
    assert {"steps", "rhs", "failed", "J", "relative"} <= set(rows[0])
    md = (out / "report.md").read_text()
    assert "4 cells: 4 ok, 0 errors" in md
    for r in rows:  # one table row per cell with its figures
        assert f"| pend | {r['--integrator']} | {r['--muscle-mass-kg']} | ok |" in md and r["steps"] in md
    # one figure per numeric column that varies and grid flag, each a complete SVG
    cols = report.numeric_columns(res.rows)
    assert "steps" in cols and "frames" not in cols
    if report.find_gnuplot() is None:
        assert "gnuplot not found" in md
    else:
        assert len(res.figures) == 2 * len(cols)
        for f in res.figures:
            text = open(f).read()
            assert text.startswith("<?xml") and text.rstrip().endswith("</svg>")
            assert os.path.relpath(f, out) in md
    # what a figure plots is the table's numbers: steps against the integrator, per trial
    labels, series = report.figure_data(res.rows, res.flags, "steps", "--integrator")
    assert labels == ["rk45", "euler"]
    assert sorted(series["pend"]) == sorted(([0, 1][r["--integrator"] == "euler"], float(r["steps"])) for r in rows)
    # euler's fixed 1 ms steps: 200 in 0.2 s
    assert all(y == 200.0 for x, y in series["pend"] if x == 1)
    # Parquet where python3-pyarrow is installed, nothing otherwise
    try:
        import pyarrow.parquet
    except ImportError:
        assert res.parquet_path is None and not (out / "results.parquet").exists()
    else:
        t = pyarrow.parquet.read_table(res.parquet_path).to_pylist()
        assert t == rows


def test_reserved_trial_names(tmp_path):
    study = make_study(str(tmp_path), [dict(id_trial(), name="report")], {})
    with pytest.raises(rb.StudyError, match="'report' is taken"):
        rb.load_study(study)

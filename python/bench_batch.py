#!/usr/bin/python3
"""Scale of `redmax batch` (docs/python.md §4): tasks/s, CPU efficiency and per-task overhead on 1
and 2 local workers, against calling the library in-process (redmax.inverse_dynamics) and against
`redmax id` run serially. usage: python/bench_batch.py [BUILD_DIR] [CELLS]"""
import json
import os
import subprocess
import sys
import tempfile
import time

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
build = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "build"))
cells = int(sys.argv[2]) if len(sys.argv) > 2 else 40
sys.path.insert(0, os.path.join(build, "python"))
os.environ["REDMAX_EXE"] = os.path.join(build, "cli", "redmax")
import redmax  # noqa: E402


def main():
    leg, swing = os.path.join(root, "osim_models", "running_leg.osim"), os.path.join(root, "osim_models", "running_leg_swing.mot")
    tmp = tempfile.mkdtemp(prefix="redmax-bench-")
    study = os.path.join(tmp, "study.json")
    with open(study, "w") as fh:
        json.dump({"trials": [{"name": "leg", "command": "id", "args": ["--model", leg, "--coordinates", swing,
                                                                       "--muscle-mass", "physiological"]}],
                   "grid": {"--mass-points": [str(5 + i) for i in range(cells)]}}, fh)

    if redmax._core is not None:
        t = time.perf_counter()
        for i in range(cells):
            redmax.inverse_dynamics(leg, coordinates=swing, muscle_mass="physiological", mass_points=5 + i)
        lib = (time.perf_counter() - t) / cells
        print(f"library in-process: {lib * 1e3:.1f} ms per call")
    else:
        lib = None
    t = time.perf_counter()
    for i in range(cells):
        subprocess.run([os.environ["REDMAX_EXE"], "id", "--model", leg, "--coordinates", swing, "--muscle-mass",
                        "physiological", "--mass-points", str(5 + i), "--quiet", "--out", os.path.join(tmp, "x.sto")],
                       check=True)
    cli = (time.perf_counter() - t) / cells
    print(f"redmax id subprocess: {cli * 1e3:.1f} ms per call")
    for w in (1, 2):
        from distributed import Client, LocalCluster
        with LocalCluster(n_workers=w, threads_per_worker=1, processes=True, dashboard_address=None) as c, Client(c) as cl:
            cl.submit(sum, [1]).result()  # the cluster is up: time the study only
            t = time.perf_counter()
            r = redmax.batch(study, os.path.join(tmp, f"w{w}"), client=cl, progress=None)
            el = time.perf_counter() - t
        busy = sum(x["wall_s"] for x in r.rows)
        per_task = el * w / cells
        print(f"{w} worker(s): {cells} tasks in {el:.2f} s = {cells / el:.1f} tasks/s; CPU efficiency "
              f"{busy / (w * el):.0%} (task wall / worker time); per task {per_task * 1e3:.1f} ms worker time, overhead "
              f"{(per_task - cli) * 1e3:+.1f} ms vs redmax id, "
              + (f"{(per_task - lib) * 1e3:+.1f} ms vs the library" if lib else "library not built"))


if __name__ == "__main__":  # Dask's worker processes re-import this file
    main()

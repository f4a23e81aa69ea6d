"""A batch study on a local Dask cluster from Python (docs/python.md §3): the running leg's ID
with the mass of tibia_r moved into its muscles, over a grid of fractions and point counts.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/batch_study.py [OUT_DIR]

OUT_DIR (default: a temporary folder) receives study.json, results.csv, report.md with its
figures, and one folder per cell. A script that starts a local Dask cluster runs its work under
`if __name__ == "__main__":` (Dask's worker processes import the main module again).
"""
import json
import os
import sys
import tempfile

import redmax

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="redmax_batch_")
    os.makedirs(out, exist_ok=True)
    study = {
        "trials": [{"name": "leg", "command": "id",
                    "args": ["--model", os.path.join(ROOT, "osim_models", "running_leg.osim"),
                             "--coordinates", os.path.join(ROOT, "osim_models", "running_leg_swing.mot")]}],
        "grid": {"--muscle-mass": ["transfer"], "--transfer-body": ["tibia_r"],
                 "--transfer-fraction": ["0.2", "0.4", "0.8"], "--mass-points": ["10", "20"]},
    }
    path = os.path.join(out, "study.json")
    with open(path, "w") as fh:
        json.dump(study, fh, indent=1)

    res = redmax.batch(path, os.path.join(out, "results"), workers=2, progress=None)
    print(f"batch: {len(res.rows)} cells, {res.errors} errors -> {res.csv_path}")
    print(f"report: {res.report_path} ({len(res.figures)} figures)")
    # each cell's output is an ordinary .sto: the knee's peak against the fraction moved
    for r in res.rows:
        t = redmax.read_storage(os.path.join(out, "results", r["output"]))
        print(f"  {r['cell']}: knee peak {abs(t['knee_angle_r_moment']).max():.4f} N m")
    return 1 if res.errors else 0


if __name__ == "__main__":
    sys.exit(main())

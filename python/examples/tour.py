"""The README's five-minute tour in Python (docs/python.md §2), on the bundled running leg.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/tour.py [OUT_DIR]

Run from anywhere; OUT_DIR (default: a temporary folder) receives id.sto, id_mass.sto and len.sto.
"""
import os
import sys
import tempfile

import redmax

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
LEG = os.path.join(ROOT, "osim_models", "running_leg.osim")
SWING = os.path.join(ROOT, "osim_models", "running_leg_swing.mot")
out = sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="redmax_tour_")
os.makedirs(out, exist_ok=True)

# `redmax convert`: the model's summary and description
m = redmax.Model(LEG)
print(m.summary["text"].splitlines()[0])
print(f"{m.summary['bodies']} bodies, {m.summary['coordinates']} coordinates, {m.summary['muscles']} muscles")

# `redmax id`: OpenSim's InverseDynamicsTool, then with each muscle's physiological mass
r = redmax.inverse_dynamics(m, coordinates=SWING)
r.write(os.path.join(out, "id.sto"))
rm = redmax.inverse_dynamics(m, coordinates=SWING, muscle_mass="physiological", mass_points=20)
rm.write(os.path.join(out, "id_mass.sto"))
knee, knee_m = r["knee_angle_r_moment"], rm["knee_angle_r_moment"]
print(f"id: {len(r)} frames, {len(r.labels)} coordinates; knee peak {abs(knee).max():.4g} -> "
      f"{abs(knee_m).max():.4g} N m with muscle mass")

# `redmax lengths`: musculotendon lengths, wrapping as OpenSim does
L = redmax.path_lengths(m, SWING)
L.write(os.path.join(out, "len.sto"))
print("lengths: " + ", ".join(f"{c} {L[c].min():.4f}-{L[c].max():.4f} m" for c in L.labels))

# `redmax validate`: the core against Simbody at zero muscle mass, then the tibia transfer sweep
# (no_plots: the figures are gnuplot's; the numbers are in summary.json either way)
v = redmax.validate(m, SWING, report=os.path.join(out, "zero_mass"), no_plots=True)
worst = max(c["worst_column"]["rms_rel"] for c in v.summary["comparisons"])
print(f"validate: {'PASS' if v.passed else 'FAIL'}, core vs Simbody worst rms/peak {worst:.3g}")
s = redmax.validate(m, SWING, report=os.path.join(out, "tibia_sweep"), no_plots=True, muscle_mass="transfer",
                    transfer_body="tibia_r", mass_sweep=[0, 0.2, 0.4, 0.6, 0.8])
print(f"sweep: {'PASS' if s.passed else 'FAIL'}, {len(s.summary['mass_sweep']['values'])} transfer fractions")

# pandas, where python3-pandas is installed
try:
    df = rm.to_pandas()
    print(f"pandas: {df.shape[0]} rows x {df.shape[1]} columns, index '{df.index.name}'")
except ImportError:
    print("pandas: not installed")
print(f"tour: done -> {out}")

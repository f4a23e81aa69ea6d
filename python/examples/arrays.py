"""Inverse dynamics of NumPy arrays and the muscles' mass points (docs/python.md §2).

    PYTHONPATH=build/python /usr/bin/python3 python/examples/arrays.py

The trial's own inputs (q, qdot, qddot per frame) solved as arrays give the trial's values bit for
bit; then the same motion twice as fast (qdot x 2, qddot x 4), and where the mass points sit.
"""
import os

import numpy

import redmax

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
LEG = os.path.join(ROOT, "osim_models", "running_leg.osim")
SWING = os.path.join(ROOT, "osim_models", "running_leg_swing.mot")
mass = dict(muscle_mass="physiological", mass_points=20)

trial = redmax.inverse_dynamics(LEG, coordinates=SWING, with_inputs=True, **mass)
q, qdot, qddot = trial.inputs["q"], trial.inputs["qdot"], trial.inputs["qddot"]
same = redmax.inverse_dynamics(LEG, q=q, qdot=qdot, qddot=qddot, time=trial.time, **mass)
print(f"arrays: {q.shape[0]} frames x {q.shape[1]} coordinates; equal to the trial: "
      f"{numpy.array_equal(same.values, trial.values)}")

fast = redmax.inverse_dynamics(LEG, q=q, qdot=2 * qdot, qddot=4 * qddot, time=trial.time / 2, **mass)
k = trial.labels.index("knee_angle_r_moment")
print(f"twice as fast: knee peak {abs(trial.values[:, k]).max():.4g} -> {abs(fast.values[:, k]).max():.4g} N m")

pts = redmax.mass_points(LEG, q[[0, -1]], **mass)
for name, mp in pts.items():
    travel = numpy.linalg.norm(mp.points[1] - mp.points[0], axis=1)
    print(f"mass points: {name} (Type {mp.path_type}) {mp.mass.sum():.4g} kg in {len(mp.alpha)} points, "
          f"moved {travel.min():.3f}-{travel.max():.3f} m over the swing")
print("arrays: done")

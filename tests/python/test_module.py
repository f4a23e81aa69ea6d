"""The redmax module (pybind11): the README's tour in Python, and inverse dynamics equal to the CLI's
`redmax id --full-precision` on sets A, E, F to the last digit (docs/python.md §2)."""
import subprocess
import threading

import numpy
import pytest

from conftest import LEG, SWING, shared, skip_module_without_core

import redmax

skip_module_without_core()

CMC = "Tutorials/Computed_Muscle_Control/OutputReference/"
E = "Pipelines/Gait2392_Simbody/"
F = "Pipelines/Gait10dof18musc/OutputReference/"
SETS = {
    "A": ("opensim-models@a26e12c/" + CMC + "arm26.osim", "opensim-models/" + CMC + "InverseKinematics/arm26_InverseKinematics.mot",
          None, 0.0, 1.0, 6.0),
    "E": ("opensim-models@a26e12c/" + E + "OutputReference/subject01_simbody.osim", "opensim-models/" + E + "subject01_walk1_ik.mot",
          "opensim-models/" + E + "subject01_walk1_grf.xml", 0.4, 1.6, 6.0),
    "F": ("opensim-models@a26e12c/" + F + "subject01.osim", "opensim-models/" + F + "IK/subject01_walk_IK.mot",
          "opensim-models/" + F + "ExperimentalData/subject01_walk_grf.xml", 0.0, 2.5, 6.0),
}


def cli_id(exe, tmp_path, args):
    out = tmp_path / "cli.sto"
    subprocess.run([exe, "id", *args, "--full-precision", "--quiet", "--out", str(out)], check=True)
    return redmax.read_storage(out)


@pytest.mark.parametrize("name", sorted(SETS))
def test_id_equals_cli_on_shared_sets(name, tmp_path, redmax_exe):
    model, coords, loads, t0, t1, lowpass = SETS[name]
    model, coords = shared(model), shared(coords)
    args = ["--model", model, "--coordinates", coords, "--t0", str(t0), "--t1", str(t1), "--lowpass", str(lowpass)]
    if loads:
        loads = shared(loads)
        args += ["--external-loads", loads]
    ref = cli_id(redmax_exe, tmp_path, args)
    r = redmax.inverse_dynamics(redmax.Model(model), coordinates=coords, external_loads=loads, lowpass=lowpass,
                                t0=t0, t1=t1)
    assert r.labels == ref.labels
    assert numpy.array_equal(r.time, ref.time)
    assert numpy.array_equal(r.values, ref.values)  # %.16e round-trips: the last digit


def test_tour_in_python(tmp_path, redmax_exe):
    m = redmax.Model(LEG)
    assert m.summary["name"] == "running_leg" and m.summary["bodies"] == 4 and m.summary["coordinates"] == 11
    assert "model 'running_leg'" in m.summary["text"]
    assert [c["name"] for c in m.description["coordinates"]][0] == "pelvis_tilt"
    r = redmax.inverse_dynamics(m, coordinates=SWING, muscle_mass="physiological", mass_points=10)
    assert r.values.shape == (81, 11) and r.time.shape == (81,)
    ref = cli_id(redmax_exe, tmp_path, ["--model", LEG, "--coordinates", SWING, "--muscle-mass", "physiological",
                                        "--mass-points", "10"])
    assert numpy.array_equal(r.values, ref.values)
    df = r.to_pandas()
    assert list(df.columns) == r.labels and df.index.name == "time"
    assert numpy.array_equal(r["knee_angle_r_moment"], df["knee_angle_r_moment"].to_numpy())
    # .sto out and back: %.16e keeps every digit
    r.write(tmp_path / "py.sto", full_precision=True)
    back = redmax.read_storage(tmp_path / "py.sto")
    assert back.labels == r.labels and numpy.array_equal(back.values, r.values)
    # path lengths as `redmax lengths`
    L = redmax.path_lengths(m, SWING)
    subprocess.run([redmax_exe, "lengths", "--model", LEG, "--coordinates", SWING, "--full-precision", "--out",
                    str(tmp_path / "len.sto")], check=True, capture_output=True)
    ref_len = redmax.read_storage(tmp_path / "len.sto")
    assert L.labels == ref_len.labels and numpy.array_equal(L.values, ref_len.values)


def test_errors_carry_file_and_line(tmp_path):
    bad = tmp_path / "bad.osim"
    bad.write_text("<OpenSimDocument Version=\"40000\">\n<Model name=\"x\">\n<BodySet>\n</Model>\n")
    with pytest.raises(redmax.ConvertError, match=r"bad\.osim:\d+"):
        redmax.Model(bad)
    with pytest.raises(ValueError, match="missing.mot"):  # the CLI's --coordinates check
        redmax.inverse_dynamics(LEG, coordinates=str(tmp_path / "missing.mot"))
    with pytest.raises(ValueError):
        redmax.inverse_dynamics(LEG, coordinates=SWING, muscle_mass="heavy")


def test_threads_run_with_the_gil_released():
    results = [None] * 4

    def work(i):
        results[i] = redmax.inverse_dynamics(LEG, coordinates=SWING, muscle_mass="physiological").values

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(numpy.array_equal(results[0], x) for x in results[1:])


def test_every_public_function_has_a_docstring():
    import inspect
    import redmax.report
    import redmax.study
    missing = []
    for mod in (redmax, redmax.study, redmax.report):
        for name, obj in vars(mod).items():
            if name.startswith("_") or getattr(obj, "__module__", "") != mod.__name__:
                continue
            if inspect.isfunction(obj) or inspect.isclass(obj):
                if not inspect.getdoc(obj):
                    missing.append(f"{mod.__name__}.{name}")
            if inspect.isclass(obj):
                for m, f in vars(obj).items():
                    if not m.startswith("_") and (inspect.isfunction(f) or isinstance(f, property)) \
                            and not inspect.getdoc(f):
                        missing.append(f"{mod.__name__}.{name}.{m}")
    assert missing == []

"""The rest of the Python API against the command line on the same input (docs/python.md §2):
inverse dynamics of arrays against the trial, mass-point positions against an independent
computation on the path polyline, forward, analyze and validate against `redmax forward`,
`analyze` and `validate`, keyword errors with the CLI's messages."""
import json
import os
import subprocess

import numpy
import pytest

from conftest import LEG, MODELS, SWING, shared, skip_module_without_core

import redmax

skip_module_without_core()
E = "opensim-models/Pipelines/Gait2392_Simbody/"
FORWARD_SETUP = "opensim-core/Applications/Forward/tests/resources/arm26_Setup_Forward.xml"
ANALYZE_SETUP = "opensim-core/Applications/Analyze/tests/resources/arm26_Setup_StaticOptimization.xml"


def run(exe, *args):
    p = subprocess.run([exe, *args], capture_output=True, text=True)
    return p


def data_lines(path):
    """The rows of a .sto below endheader (the numbers as the writer printed them)."""
    with open(path) as fh:
        text = fh.read()
    return text.split("endheader\n", 1)[1].splitlines()


# --- inverse dynamics of arrays ------------------------------------------------------------

def test_id_of_arrays_equals_the_trial():
    # with muscle mass (top:K ranks over the frames: the arrays' rows are the trial's frames)
    trial = redmax.inverse_dynamics(LEG, coordinates=SWING, muscle_mass="physiological", muscles="top:3",
                                    with_inputs=True)
    i = trial.inputs
    assert i["q"].shape == trial.values.shape == (81, 11) and i["loads"] == []
    arrays = redmax.inverse_dynamics(LEG, q=i["q"], qdot=i["qdot"], qddot=i["qddot"], time=trial.time,
                                     muscle_mass="physiological", muscles="top:3")
    assert arrays.labels == trial.labels
    assert numpy.array_equal(arrays.values, trial.values)  # bit for bit
    # the library's buffers, not copies: a column is a view of the values
    assert not trial.values.flags.owndata and numpy.shares_memory(trial["knee_angle_r_moment"], trial.values)
    # the same arrays without muscle mass differ (the mass points are in the arrays' run)
    bare = redmax.inverse_dynamics(LEG, q=i["q"], qdot=i["qdot"], qddot=i["qddot"])
    assert not numpy.array_equal(bare.values, trial.values)
    assert numpy.array_equal(bare.time, numpy.arange(81.0))


def test_id_of_arrays_with_loads_equals_set_e():
    model, coords, loads = shared(E + "OutputReference/subject01_simbody.osim"), shared(E + "subject01_walk1_ik.mot"), \
        shared(E + "subject01_walk1_grf.xml")
    trial = redmax.inverse_dynamics(model, coordinates=coords, external_loads=loads, lowpass=6, t0=0.4, t1=1.6,
                                    with_inputs=True)
    i = trial.inputs
    assert [ld["body"] for ld in i["loads"]] == ["calcn_r", "calcn_l"]
    arrays = redmax.inverse_dynamics(model, q=i["q"], qdot=i["qdot"], qddot=i["qddot"], time=trial.time,
                                     loads=i["loads"])
    assert numpy.array_equal(arrays.values, trial.values)
    # the loads as arrays act as forces should: the pelvis translations' residuals (ground axes)
    # without them exceed the trial's by the summed ground reactions (peak 924 N vertical), to
    # 1e-12 N (measured 5.7e-13 N)
    without = redmax.inverse_dynamics(model, q=i["q"], qdot=i["qdot"], qddot=i["qddot"], time=trial.time)
    for axis, c in enumerate(("pelvis_tx_force", "pelvis_ty_force", "pelvis_tz_force")):
        f = sum(ld["force"][:, axis] for ld in i["loads"])
        assert numpy.abs(without[c] - trial[c] - f).max() < 1e-12


def test_id_of_arrays_refuses_bad_input():
    q = numpy.zeros((3, 11))
    with pytest.raises(ValueError, match="qdot must be frames x 11"):
        redmax.inverse_dynamics(LEG, q=q, qdot=numpy.zeros((3, 10)), qddot=q)
    with pytest.raises(ValueError, match="--lowpass does not apply"):
        redmax.inverse_dynamics(LEG, q=q, qdot=q, qddot=q, lowpass=6)
    with pytest.raises(ValueError, match="no such body"):
        redmax.inverse_dynamics(LEG, q=q, qdot=q, qddot=q, loads=[{"body": "nose", "force": numpy.zeros((3, 3))}])
    with pytest.raises(ValueError, match=r"nope\.osim: no such file"):  # the CLI's --model check
        redmax.inverse_dynamics(os.path.join(MODELS, "nope.osim"), q=q, qdot=q, qddot=q)


def test_id_of_arrays_malformed_model(tmp_path):
    bad = tmp_path / "bad.osim"
    bad.write_text("<OpenSimDocument Version=\"40000\">\n<Model name=\"x\">\n<BodySet>\n</Model>\n")
    q = numpy.zeros((1, 1))
    with pytest.raises(redmax.ConvertError, match=r"bad\.osim:\d+"):
        redmax.inverse_dynamics(bad, q=q, qdot=q, qddot=q)
    with pytest.raises(redmax.ConvertError, match=r"bad\.osim:\d+"):
        redmax.mass_points(bad, q, muscle_mass="physiological")


# --- mass points -------------------------------------------------------------------------

def polyline_point(path, alpha):
    """The point at arc-length fraction alpha along a polyline (P x 3), computed here."""
    seg = numpy.linalg.norm(numpy.diff(path, axis=0), axis=1)
    s = alpha * seg.sum()
    cum = numpy.concatenate([[0.0], numpy.cumsum(seg)])
    i = min(numpy.searchsorted(cum, s, side="right") - 1, len(seg) - 1)
    return path[i] + (s - cum[i]) / seg[i] * (path[i + 1] - path[i])


def test_mass_points_lie_on_the_path():
    trial = redmax.inverse_dynamics(LEG, coordinates=SWING, with_inputs=True)
    q = trial.inputs["q"][::10]
    pts = redmax.mass_points(LEG, q, muscle_mass="physiological", mass_points=10)
    assert list(pts) == [m["name"] for m in redmax.Model(LEG).description["muscles"]]
    lengths = redmax.path_lengths(LEG, SWING)
    for name, mp in pts.items():
        assert mp.points.shape == (len(q), 10, 3)
        # the fibre region, evenly: alpha in ((1 - phi) / 2, (1 + phi) / 2), equal steps
        assert numpy.allclose(numpy.diff(mp.alpha), mp.alpha[1] - mp.alpha[0], rtol=0, atol=1e-15)
        assert mp.mass.sum() > 0
        for k in range(len(q)):
            span = mp.alpha[-1] - mp.alpha[0]
            if mp.path_type in ("I", "II"):
                # straight and via-point paths: each point at its arc fraction of the polyline
                # (measured 5.6e-17 m), and the polyline is `redmax lengths`' path (measured 0)
                for a, x in zip(mp.alpha, mp.points[k]):
                    assert numpy.abs(x - polyline_point(mp.path[k], a)).max() < 5e-16
                L = numpy.linalg.norm(numpy.diff(mp.path[k], axis=0), axis=1).sum()
                assert abs(L - lengths[name][10 * k]) <= 2e-16
            else:
                # wrapping: the points leave the straight polyline for the surface (smooth model);
                # the chords between them add up to their share of OpenSim's exact wrapped length,
                # (alpha_N - alpha_1) L, to 1e-5 (measured 4.5e-6 over all 81 frames: the smooth
                # model's blend and chords against arcs)
                d = numpy.linalg.norm(numpy.diff(mp.points[k], axis=0), axis=1)
                assert (d > 0).all() and abs(d.sum() / (span * lengths[name][10 * k]) - 1) < 1e-5
    # without muscle mass no muscle carries points
    assert redmax.mass_points(LEG, q) == {}


# --- forward, analyze, validate against the command line ------------------------------------

def test_forward_equals_cli(tmp_path, redmax_exe):
    setup = shared(FORWARD_SETUP)
    flags = dict(muscle_class="Thelen2003Muscle_Deprecated", integrator="cvode")
    p = run(redmax_exe, "forward", "--setup", setup, "--muscle-class", flags["muscle_class"], "--integrator", "cvode",
            "--out-dir", str(tmp_path / "cli"), "--view")
    assert p.returncode == 0, p.stderr
    f = redmax.forward(setup=setup, out_dir=tmp_path / "py", view=True, **flags)
    # the module finds the page files as the executable does, and writes the same view
    assert f.files[-1] == str(tmp_path / "py" / "arm26_view" / "index.html")
    assert (tmp_path / "py" / "arm26_view" / "data.js").read_bytes() == \
        (tmp_path / "cli" / "arm26_view" / "data.js").read_bytes()
    assert f.states.values.shape == (101, 16) and f.controls.values.shape[1] == 6
    assert f"{f.steps} steps, {f.rhs_evals} rhs" in p.stdout  # the same integration
    for table, name in ((f.states, "arm26_states.sto"), (f.controls, "arm26_controls.sto")):
        # the returned arrays print as the CLI's file: every digit the CLI writes (%.8e)
        assert f.decimals == 8
        table.write(tmp_path / name, decimals=f.decimals, scientific=True)
        assert data_lines(tmp_path / name) == data_lines(tmp_path / "cli" / name)
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()
    # without out_dir nothing is written
    assert redmax.forward(setup=setup, report_interval=0.5, **flags).files == []


def test_analyze_equals_cli(tmp_path, redmax_exe):
    setup = shared(ANALYZE_SETUP)
    p = run(redmax_exe, "analyze", "--setup", setup, "--muscle-class", "Thelen2003Muscle_Deprecated", "--out-dir",
            str(tmp_path / "cli"))
    assert p.returncode == 0, p.stderr
    a = redmax.analyze(setup=setup, muscle_class="Thelen2003Muscle_Deprecated", out_dir=str(tmp_path / "py"))
    assert a.failed == 0 and all(a.converged) and len(a.time) == 61
    assert a.labels == ["TRIlong", "TRIlat", "TRImed", "BIClong", "BICshort", "BRA"]
    for table, name in ((a.activation, "arm26_StaticOptimization_activation.sto"),
                        (a.force, "arm26_StaticOptimization_force.sto")):
        assert a.decimals == 20  # the setup's output_precision: %.20f, every digit of a double here
        table.write(tmp_path / name, decimals=a.decimals)
        assert data_lines(tmp_path / name) == data_lines(tmp_path / "cli" / name)
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()
    # the forces are the activations times the muscles' forces: at most 1 in activation
    assert (a.activation.values <= 1 + 1e-9).all()


def test_validate_equals_cli(tmp_path, redmax_exe):
    args = ["--model", LEG, "--coordinates", SWING, "--muscle-mass", "physiological", "--no-plots"]
    p = run(redmax_exe, "validate", *args, "--report", str(tmp_path / "cli"))
    assert p.returncode == 0, p.stderr
    v = redmax.validate(model=LEG, coordinates=SWING, muscle_mass="physiological", no_plots=True,
                        report=tmp_path / "py")
    assert v.passed and v.summary["passed"] is True
    with open(tmp_path / "cli" / "summary.json") as fh:
        cli = json.load(fh)
    assert v.summary["comparisons"] == cli["comparisons"]
    # the comparison lines of the printed summary (the engines' lines carry timings)
    cmp = [line for line in p.stdout.splitlines() if line.startswith("core_vs_")]
    assert cmp and cmp == [line for line in v.text.splitlines() if line.startswith("core_vs_")]
    for f in ("core_id.sto", "simbody_id.sto", "core_mass_id.sto"):
        assert (tmp_path / "py" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes()


def test_keywords_are_the_cli_flags(tmp_path):
    setup = shared(ANALYZE_SETUP)
    with pytest.raises(ValueError, match="--integrator: must be"):  # the CLI's own check
        redmax.forward(setup=shared(FORWARD_SETUP), integrator="leapfrog")
    with pytest.raises(ValueError, match="forward needs --setup"):
        redmax.forward()
    with pytest.raises(ValueError, match="view=True needs out_dir"):  # a view is never dropped
        redmax.forward(setup=shared(FORWARD_SETUP), view=True)
    with pytest.raises(ValueError, match="muscle-class"):
        redmax.analyze(setup=setup, muscle_class="Nope")
    with pytest.raises(ValueError, match="--mass-sweep needs --muscle-mass"):
        redmax.validate(model=LEG, coordinates=SWING, mass_sweep=[0, 0.5], report=tmp_path / "r")
    with pytest.raises(ValueError, match="not expected|unknown|--colour"):
        redmax.validate(model=LEG, coordinates=SWING, report=tmp_path / "r", colour="red")
    # a model the class refuses: FILE:LINE as the CLI prints it, nothing written
    with pytest.raises(redmax.ConvertError, match=r"arm26\.osim:1122: Thelen2003Muscle muscle 'TRIlong'"):
        redmax.analyze(setup=setup, muscle_class="Thelen2003Muscle", out_dir=tmp_path / "bad")
    assert not (tmp_path / "bad").exists()


def test_a_diverging_forward_run_raises_error(tmp_path, redmax_exe):
    pendulum = shared("opensim-models/Models/DoublePendulum/double_pendulum.osim")
    (tmp_path / "controls.xml").write_text(
        '<ControlSet><objects><ControlLinear name="Torq1"><x_nodes>\n'
        '<ControlLinearNode><t>0</t><value>1e200</value></ControlLinearNode>\n'
        '</x_nodes></ControlLinear></objects></ControlSet>\n')
    setup = tmp_path / "setup.xml"
    setup.write_text('<OpenSimDocument Version="40000">\n<ForwardTool name="pend">\n'
                     f'<model_file>{pendulum}</model_file>\n<results_directory>res</results_directory>\n'
                     '<initial_time>0</initial_time>\n<final_time>0.2</final_time>\n'
                     '<ControllerSet><objects><ControlSetController name="c">\n'
                     '<controls_file>controls.xml</controls_file>\n'
                     '</ControlSetController></objects></ControllerSet>\n</ForwardTool>\n</OpenSimDocument>\n')
    p = run(redmax_exe, "forward", "--setup", str(setup), "--integrator", "euler")
    assert p.returncode == 1
    message = p.stderr.split("error: ", 1)[1].strip()
    with pytest.raises(redmax.Error) as e:
        redmax.forward(setup=str(setup), integrator="euler", out_dir=tmp_path / "out")
    assert str(e.value) == message  # "setup.xml: euler: diverged: q[0] = ... at t = 0.001 ..."
    assert "diverged" in message and "t = 0.001" in message
    assert not (tmp_path / "out").exists() and not (tmp_path / "res").exists()  # nothing written

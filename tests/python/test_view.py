"""`redmax view` (docs/view.md): the folder it writes, loaded from disk by headless Chromium.

The page reports what it drew as JSON in <pre id="status"> (view/web/view.js), which
`chromium --dump-dom` reads back; screenshots are taken at two times through #t=SECONDS. Every
check that needs a browser skips with a message when Debian's `chromium` is not installed.
"""
import json
import os
import re
import shutil
import subprocess
import tempfile
import zlib

import numpy as np
import pytest

from conftest import LEG, MODELS, SWING, shared

WRAP_PENDULUM = os.path.join(MODELS, "double_pendulum_wrap.osim")


@pytest.fixture(scope="module")
def chromium():
    exe = shutil.which("chromium")
    if not exe:
        pytest.skip("chromium not installed (Debian package `chromium`, scripts/setup installs it): "
                    "the page checks of `redmax view` are skipped")
    return exe


def run(*args):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=120)


def browse(chromium, jobs):
    """Run Chromium on each (url, mode, out) at once: mode 'dom' returns the DOM and stderr,
    'png' writes a screenshot of a 900x560 window at half scale (450x280 pixels, to keep decoding
    short) to out. Returns {out-or-url: (stdout, stderr)}."""
    procs = []
    for url, mode, out in jobs:
        profile = tempfile.mkdtemp(prefix="redmax-chromium-")
        cmd = [chromium, "--headless", "--no-sandbox", "--enable-unsafe-swiftshader", "--no-first-run",
               "--hide-scrollbars", "--window-size=900,560", f"--user-data-dir={profile}"]
        cmd += ["--dump-dom"] if mode == "dom" else [f"--screenshot={out}", "--force-device-scale-factor=0.5"]
        procs.append((out or url, profile, subprocess.Popen(cmd + [url], stdout=subprocess.PIPE,
                                                             stderr=subprocess.PIPE, text=True)))
    results = {}
    for key, profile, p in procs:
        out, err = p.communicate(timeout=120)
        shutil.rmtree(profile, ignore_errors=True)
        results[key] = (out, err)
    return results


def page_status(dom):
    m = re.search(r'<pre id="status"[^>]*>(.*?)</pre>', dom, re.S)
    assert m, "the page has no status element"
    return json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&").replace("&lt;", "<")
                      .replace("&gt;", ">"))


def read_png(path):
    """RGBA or RGB 8-bit PNG (what Chromium writes) -> array rows x cols x 3."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat = 8, b""
    while pos < len(data):
        n = int.from_bytes(data[pos:pos + 4], "big")
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            width, height = int.from_bytes(body[:4], "big"), int.from_bytes(body[4:8], "big")
            assert body[8] == 8 and body[12] == 0, "8-bit non-interlaced PNG expected"
            bpp = {6: 4, 2: 3}[body[9]]
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw, stride = zlib.decompress(idat), width * bpp
    rows, prev = [], bytearray(stride)
    for r in range(height):
        f, cur = raw[r * (stride + 1)], bytearray(raw[r * (stride + 1) + 1:(r + 1) * (stride + 1)])
        if f == 2:
            cur = bytearray((np.frombuffer(cur, np.uint8) + np.frombuffer(prev, np.uint8)).tobytes())
        elif f in (1, 3, 4):  # Sub, Average, Paeth: sequential along the row
            for i in range(stride):
                a = cur[i - bpp] if i >= bpp else 0
                b = prev[i]
                if f == 1:
                    pred = a
                elif f == 3:
                    pred = (a + b) >> 1
                else:
                    c = prev[i - bpp] if i >= bpp else 0
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    pred = a if pa <= pb and pa <= pc else b if pb <= pc else c
                cur[i] = (cur[i] + pred) & 255
        rows.append(cur)
        prev = cur
    return np.frombuffer(b"".join(rows), np.uint8).reshape(height, width, bpp)[:, :, :3]


def convert_json(redmax_exe, model, tmp_path):
    out = tmp_path / (os.path.basename(model) + ".json")
    r = run(redmax_exe, "convert", model, "--json", out, "--quiet")
    assert r.returncode == 0, r.stderr
    return json.loads(out.read_text())


def view_data(folder):
    text = (folder / "data.js").read_text()
    prefix = "window.REDMAX_VIEW = "
    assert text.startswith(prefix)
    return json.loads(text[len(prefix):].rstrip().rstrip(";"))


@pytest.fixture(scope="module")
def leg_view(redmax_exe, tmp_path_factory):
    out = tmp_path_factory.mktemp("view") / "leg"
    r = run(redmax_exe, "view", LEG, "--motion", SWING, "--muscle-mass", "physiological", "--out", out)
    assert r.returncode == 0, r.stderr
    return out, r


def test_folder_is_self_contained(leg_view):
    out, r = leg_view
    assert sorted(os.listdir(out)) == ["data.js", "index.html", "three.min.js", "view.css", "view.js"]
    html = (out / "index.html").read_text()
    # nothing from the network: every script and style is a file beside the page
    assert not re.search(r'(src|href)="(https?:)?//', html)
    assert "view: 81 frames, 4 bodies (0 meshes), 4 muscles, 80 mass points" in r.stdout


def test_lengths_equal_redmax_lengths(redmax_exe, leg_view, tmp_path):
    # the page's readout is OpenSim's exact path length: the same numbers as `redmax lengths`
    out, _ = leg_view
    sto = tmp_path / "len.sto"
    r = run(redmax_exe, "lengths", "--model", LEG, "--coordinates", SWING, "--full-precision", "--quiet", "--out", sto)
    assert r.returncode == 0, r.stderr
    lines = sto.read_text().splitlines()
    header = lines.index("endheader")
    labels = lines[header + 1].split()[1:]
    table = np.array([[float(x) for x in line.split()] for line in lines[header + 2:]])
    data = view_data(out)
    assert [m["name"] for m in data["muscles"]] == labels
    page = np.array([f["lengths"] for f in data["frames"]])
    assert page.shape == table[:, 1:].shape
    # data.js keeps 8 significant digits (lengths < 1 m): measured max difference 5.0e-9 m
    assert np.max(np.abs(page - table[:, 1:])) < 2e-8
    assert np.allclose(data["times"], table[:, 0], rtol=0, atol=1e-12)


def test_page_draws_what_convert_reads(chromium, redmax_exe, leg_view, tmp_path):
    out, _ = leg_view
    res = browse(chromium, [((out / "index.html").as_uri() + "#t=0.2", "dom", None)])
    dom, err = next(iter(res.values()))
    st = page_status(dom)
    assert st["ready"], dom[:2000]
    assert st["errors"] == [] and "Uncaught" not in err, (st["errors"], err[-2000:])
    desc = convert_json(redmax_exe, LEG, tmp_path)
    assert st["muscles"] == [m["name"] for m in desc["muscles"]]
    # physiological mass: 20 points on each muscle (the wrapping ones too, over the smooth wrap model)
    assert st["mass_points"] == 20 * sum(m["is_muscle"] for m in desc["muscles"])
    assert st["bodies"] == len(desc["bodies"])
    assert st["wrap_surfaces"] == len(desc["wrap_objects"])
    assert st["t"] == pytest.approx(0.2, abs=1e-9)
    # no Geometry folder: ellipsoids, and the page says so
    assert st["meshes"] == 0 and st["ellipsoids"] == len(desc["bodies"])
    assert any("names no mesh files" in m for m in st["messages"])
    assert "names no mesh files" in dom.split('id="messages"')[1][:2000]


def test_screenshots_differ_where_the_model_moved(chromium, leg_view, tmp_path):
    out, _ = leg_view
    url = (out / "index.html").as_uri()
    shots = {name: tmp_path / f"{name}.png" for name in ("start", "start_again", "end")}
    browse(chromium, [(url + "#t=0", "png", shots["start"]), (url + "#t=0", "png", shots["start_again"]),
                      (url + "#t=0.4", "png", shots["end"])])
    start, again, end = (read_png(shots[k]) for k in ("start", "start_again", "end"))
    assert start.shape == end.shape
    # the same time draws the same picture, so a difference is the motion's
    assert np.array_equal(start, again)
    moved = np.any(start != end, axis=2)
    # the 3-D view is left of the 230 px side panel, between the message bar and the timeline (in
    # half-scale pixels)
    scene = moved[30:250, :325]
    panel = moved[30:240, 340:]
    # measured: 20.1% of the scene's pixels change between t = 0 and 0.4 s, none of the panel's
    assert 0.07 < scene.mean() < 0.6, scene.mean()
    assert panel.mean() == 0.0


def test_times_between_frames_are_interpolated(chromium, leg_view, tmp_path):
    out, _ = leg_view
    data = view_data(out)
    times, lengths = np.array(data["times"]), np.array([f["lengths"] for f in data["frames"]])
    k = len(times) // 2
    mid = 0.5 * (times[k] + times[k + 1])
    url = (out / "index.html").as_uri()
    shots = {name: tmp_path / f"{name}.png" for name in ("a", "mid", "b")}
    res = browse(chromium, [(url + f"#t={mid!r}", "dom", None), (url + f"#t={times[k]!r}", "png", shots["a"]),
                            (url + f"#t={mid!r}", "png", shots["mid"]),
                            (url + f"#t={times[k + 1]!r}", "png", shots["b"])])
    dom, err = res[url + f"#t={mid!r}"]
    st = page_status(dom)
    assert st["ready"] and st["errors"] == [], (st["errors"], err[-2000:])
    assert st["between"] == [k, k + 1] and st["t"] == pytest.approx(mid, abs=1e-12)
    # half-way lengths, to the round-off of data.js's numbers (8 significant digits)
    assert np.max(np.abs(np.array(st["lengths"]) - 0.5 * (lengths[k] + lengths[k + 1]))) < 1e-12
    assert np.max(np.abs(lengths[k + 1] - lengths[k])) > 1e-5  # the muscles moved between the frames
    a, m, b = (read_png(shots[x]) for x in ("a", "mid", "b"))
    # the in-between picture is neither frame's
    assert np.any(m != a) and np.any(m != b)


def test_forward_writes_the_runs_view(chromium, redmax_exe, tmp_path):
    setup = shared("opensim-core/Applications/Forward/tests/resources/arm26_Setup_Forward.xml")
    r = run(redmax_exe, "forward", "--setup", setup, "--muscle-class", "Thelen2003Muscle_Deprecated", "--integrator",
            "cvode", "--muscle-mass", "physiological", "--out-dir", tmp_path / "fw", "--view")
    assert r.returncode == 0, r.stderr
    out = tmp_path / "fw" / "arm26_view"
    data = view_data(out)
    points = sum(m["mass_points"] for m in data["muscles"])
    assert f"-> {out}/index.html (101 frames, 6 muscles, {points} mass points)" in r.stdout
    states = tmp_path / "fw" / "arm26_states.sto"
    lines = states.read_text().splitlines()
    table = np.array([[float(x) for x in line.split()] for line in lines[lines.index("endheader") + 2:]])
    assert np.allclose(data["times"], table[:, 0], rtol=0, atol=1e-12)
    # the same page as `redmax view` of the model along the states file forward wrote
    model = os.path.join(os.path.dirname(setup), "arm26.osim")
    v = run(redmax_exe, "view", model, "--motion", states, "--muscle-mass", "physiological", "--out", tmp_path / "v")
    assert v.returncode == 0, v.stderr
    other = view_data(tmp_path / "v")
    a = np.array([f["lengths"] for f in data["frames"]])
    b = np.array([f["lengths"] for f in other["frames"]])
    assert [m["mass_points"] for m in other["muscles"]] == [m["mass_points"] for m in data["muscles"]]
    # every muscle carries its 20 points or names why it is lumped
    assert all((m["mass_points"] == 20) != bool(m["lumped_why"]) for m in data["muscles"]), data["muscles"]
    # data.js keeps 8 significant digits: measured max difference 1.0e-8 m (one last digit)
    assert a.shape == b.shape and np.max(np.abs(a - b)) < 2e-8
    assert np.ptp(a, axis=0).max() > 1e-3  # the arm moved
    dom, err = next(iter(browse(chromium, [((out / "index.html").as_uri() + "#t=0.5", "dom", None)]).values()))
    st = page_status(dom)
    assert st["ready"] and st["errors"] == [], (st["errors"], err[-2000:])
    assert st["muscles"] == [m["name"] for m in data["muscles"]] and st["mass_points"] == points


def test_malformed_motion_is_refused(redmax_exe, tmp_path):
    bad = tmp_path / "bad.mot"
    bad.write_text("bad\nversion=1\nnRows=2\nnColumns=2\ninDegrees=yes\nendheader\ntime\tknee_angle_r\n0\t1\n0.1\tx\n")
    out = tmp_path / "v"
    r = run(redmax_exe, "view", LEG, "--motion", bad, "--out", out)
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith("error: ") and "bad.mot" in r.stderr
    assert not out.exists() and os.listdir(tmp_path) == ["bad.mot"]


def test_motion_without_coordinates_is_refused(redmax_exe, tmp_path):
    other = tmp_path / "other.mot"
    other.write_text("other\nversion=1\nnRows=1\nnColumns=2\ninDegrees=no\nendheader\ntime\tnothing\n0\t1\n")
    r = run(redmax_exe, "view", LEG, "--motion", other, "--out", tmp_path / "v")
    assert r.returncode == 2 and "no column names a coordinate" in r.stderr, r.stderr
    assert not (tmp_path / "v").exists()


def test_other_folder_is_not_replaced(redmax_exe, tmp_path):
    (tmp_path / "keep.txt").write_text("mine")
    r = run(redmax_exe, "view", LEG, "--out", tmp_path)
    assert r.returncode == 2 and "not an earlier view" in r.stderr
    assert os.listdir(tmp_path) == ["keep.txt"]


def test_meshes_beside_the_model_are_drawn(chromium, redmax_exe, tmp_path):
    # the wrapping pendulum with an OpenSim 4 <Mesh> on link1 and its .obj in Geometry/: drawn as a
    # mesh; a second, absent mesh on link2 gives an ellipsoid and a message
    text = open(WRAP_PENDULUM).read()
    mesh = ('<attached_geometry><Mesh name="m"><socket_frame>..</socket_frame>'
            '<scale_factors>1 1 1</scale_factors><mesh_file>{}</mesh_file></Mesh></attached_geometry>')
    bodies = re.findall(r'<Body name="([^"]+)">', text)
    assert len(bodies) == 2, bodies
    for body, file in zip(bodies, ("box.obj", "absent.vtp")):
        text = text.replace(f'<Body name="{body}">', f'<Body name="{body}">' + mesh.format(file), 1)
    (tmp_path / "pendulum.osim").write_text(text)
    (tmp_path / "Geometry").mkdir()
    (tmp_path / "Geometry" / "box.obj").write_text(
        "v 0 0 0\nv 0.1 0 0\nv 0.1 -0.5 0\nv 0 -0.5 0\nf 1 2 3 4\n")
    out = tmp_path / "v"
    r = run(redmax_exe, "view", tmp_path / "pendulum.osim", "--out", out)
    assert r.returncode == 0, r.stderr
    data = view_data(out)
    meshes = [b["meshes"] for b in data["bodies"]]
    assert [len(m) for m in meshes] == [1, 0]
    assert meshes[0][0]["triangles"] == [0, 1, 2, 0, 2, 3]
    assert any("1 of 2 mesh files not found" in m for m in data["messages"])
    res = browse(chromium, [(out.joinpath("index.html").as_uri(), "dom", None)])
    st = page_status(next(iter(res.values()))[0])
    assert st["errors"] == [] and st["meshes"] == 1 and st["ellipsoids"] == 1
    # no motion: one frame at the default pose, said on the page
    assert len(data["frames"]) == 1 and any("default pose" in m for m in st["messages"])


def test_validate_report_links_the_trial_view(redmax_exe, tmp_path):
    report = tmp_path / "report"
    r = run(redmax_exe, "validate", "--model", LEG, "--coordinates", SWING, "--no-simbody", "--no-plots", "--quiet",
            "--muscle-mass", "physiological", "--view", "--report", report)
    assert r.returncode == 0, r.stderr
    assert "[view/index.html](view/index.html)" in (report / "report.md").read_text()
    data = view_data(report / "view")
    assert len(data["frames"]) == 81 and data["muscle_mass"] == "physiological"
    assert sum(m["mass_points"] for m in data["muscles"]) == 80


def test_gait_study_report_links_the_trial_view(redmax_exe, leg_view, tmp_path):
    report = tmp_path / "study"
    r = run(redmax_exe, "gait-study", "--model", LEG, "--coordinates", SWING, "--t0", "0.1", "--t1", "0.125",
            "--muscle-mass", "physiological", "--no-plots", "--quiet", "--view", "--report", report)
    assert r.returncode == 0, r.stderr
    md = (report / "report.md").read_text()
    assert "[view/index.html](view/index.html)" in md and "the physiological run's" in md
    data = view_data(report / "view")
    # the view plays the whole coordinates file (81 rows), not only the study's time range
    assert len(data["frames"]) == 81 and data["muscle_mass"] == "physiological"
    # the study's physiological run's mass points: those of `redmax view --muscle-mass physiological`
    # (without --muscle-mass the study keeps the wrapping muscles lumped, and so does its view)
    alone = view_data(leg_view[0])
    assert [m["mass_points"] for m in data["muscles"]] == [m["mass_points"] for m in alone["muscles"]]
    assert sum(m["mass_points"] for m in data["muscles"]) == 80


def test_opensim3_display_geometry_is_found(redmax_exe, tmp_path):
    # arm26 as OpenSim 3 wrote it (<DisplayGeometry><geometry_file>): the humerus's .vtp in
    # Geometry/ is drawn, the bones without a file are named
    from conftest import shared
    arm = shared("opensim-models@a26e12c", "Tutorials", "Computed_Muscle_Control", "OutputReference", "arm26.osim")
    shutil.copy(arm, tmp_path / "arm26.osim")
    (tmp_path / "Geometry").mkdir()
    (tmp_path / "Geometry" / "arm_r_humerus.vtp").write_text(
        '<VTKFile type="PolyData"><PolyData><Piece NumberOfPoints="3" NumberOfPolys="1"><Points>'
        '<DataArray type="Float32" NumberOfComponents="3" format="ascii">0 0 0 0.01 0 0 0 -0.3 0</DataArray>'
        '</Points><Polys><DataArray type="Int32" Name="connectivity" format="ascii">0 1 2</DataArray>'
        '<DataArray type="Int32" Name="offsets" format="ascii">3</DataArray></Polys></Piece></PolyData></VTKFile>')
    out = tmp_path / "v"
    r = run(redmax_exe, "view", tmp_path / "arm26.osim", "--quiet", "--out", out)
    assert r.returncode == 0, r.stderr
    data = view_data(out)
    meshes = {b["name"]: [m["file"] for m in b["meshes"]] for b in data["bodies"]}
    assert meshes["r_humerus"] == ["arm_r_humerus.vtp"] and meshes["r_ulna_radius_hand"] == []
    missing = [m for m in data["messages"] if "mesh files not found" in m]
    assert len(missing) == 1 and missing[0].startswith("29 of 30 "), data["messages"]

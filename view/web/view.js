// The page of `redmax view` (docs/view.md): draws window.REDMAX_VIEW (data.js, written by
// view/view.cpp) with three.js. Everything is computed by redmax; this script only places it.
// What it drew goes into <pre id="status"> as JSON, for checks (tests/python/test_view.py).
(function () {
  "use strict";
  const started = performance.now();
  const status = { ready: false, muscles: [], mass_points: 0, bodies: 0, meshes: 0, ellipsoids: 0,
                   wrap_surfaces: 0, joint_frames: 0, frame: 0, between: [0, 0], t: 0, lengths: [],
                   messages: [], errors: [] };
  const $ = (id) => document.getElementById(id);

  function say(text, cls) {
    const p = document.createElement("p");
    if (cls) p.className = cls;
    p.textContent = text;
    $("messages").appendChild(p);
    status.messages.push(text);
  }
  function publish() {
    status.errors = window.REDMAX_ERRORS || [];
    $("status").textContent = JSON.stringify(status);
  }

  const V = window.REDMAX_VIEW;
  if (typeof THREE === "undefined") { say("three.min.js did not load: nothing can be drawn", "error"); publish(); return; }
  if (!V) { say("data.js did not load: nothing to draw (write the folder again with redmax view)", "error"); publish(); return; }
  V.messages.forEach((m) => say(m));
  document.title = "redmax view: " + V.model;
  $("title").textContent = V.model + (V.motion_file ? " / " + V.motion_file : "");

  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  } catch (e) {
    say("WebGL is not available in this browser (" + e.message + "): the model cannot be drawn", "error");
    publish();
    return;
  }
  $("scene").appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1d2024);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404048, 1.0));
  const sun = new THREE.DirectionalLight(0xffffff, 0.5);
  sun.position.set(1, 2, 1.5);
  scene.add(sun);

  const setPose = (obj, p) => { obj.position.set(p[0], p[1], p[2]); obj.quaternion.set(p[3], p[4], p[5], p[6]); };

  // the size of the model (the largest extent of one frame: body origins, centres of mass, path
  // points) and its centre relative to the first body, which the camera follows (a walking model
  // stays in view)
  let size = 0.1;
  const centreOffset = new THREE.Vector3(), point = new THREE.Vector3(), origin = new THREE.Vector3(),
        turn = new THREE.Quaternion();
  V.frames.forEach((F, f) => {
    const box = new THREE.Box3();
    V.bodies.forEach((b, i) => {
      box.expandByPoint(point.fromArray(F.bodies, 7 * i));
      turn.fromArray(F.bodies, 7 * i + 3);
      box.expandByPoint(point.fromArray(b.ellipsoid_pose).applyQuaternion(turn).add(origin.fromArray(F.bodies, 7 * i)));
    });
    F.paths.forEach((p) => { for (let i = 0; i < p.x.length; i += 3) box.expandByPoint(point.fromArray(p.x, i)); });
    size = Math.max(size, box.getSize(point).length());
    if (f === 0) centreOffset.copy(box.getCenter(point)).sub(origin.fromArray(F.bodies, 0));
  });
  const centre = new THREE.Vector3();

  // bodies: meshes, else the inertia ellipsoid; the joint frame (M) in each
  const boneMaterial = new THREE.MeshLambertMaterial({ color: 0xd8cfc0 });
  const ellipsoidMaterial = new THREE.MeshLambertMaterial({ color: 0xd8cfc0, transparent: true, opacity: 0.35, depthWrite: false });
  const bodies = V.bodies.map((b) => {
    const g = new THREE.Group();
    scene.add(g);
    b.meshes.forEach((m) => {
      const geo = new THREE.BufferGeometry();
      geo.setAttribute("position", new THREE.Float32BufferAttribute(m.vertices, 3));
      geo.setIndex(m.triangles);
      geo.computeVertexNormals();
      const mesh = new THREE.Mesh(geo, boneMaterial);
      setPose(mesh, m.pose);
      mesh.scale.fromArray(m.scale);
      g.add(mesh);
      status.meshes++;
    });
    if (!b.meshes.length && b.ellipsoid_radii[0] > 0) {
      const mesh = new THREE.Mesh(new THREE.SphereGeometry(1, 24, 16), ellipsoidMaterial);
      setPose(mesh, b.ellipsoid_pose);
      mesh.scale.fromArray(b.ellipsoid_radii);
      g.add(mesh);
      status.ellipsoids++;
    }
    const axes = new THREE.AxesHelper(0.05 * size);
    setPose(axes, b.joint_frame);
    g.add(axes);
    status.joint_frames++;
    status.bodies++;
    return g;
  });

  // wrap surfaces, fixed in their bodies (three's cylinder runs along y, OpenSim's along z)
  const wrapMaterial = new THREE.MeshBasicMaterial({ color: 0x6fa8dc, wireframe: true, transparent: true, opacity: 0.5 });
  V.wrap_surfaces.forEach((w) => {
    let geo;
    if (w.type === "cylinder") geo = new THREE.CylinderGeometry(w.radius, w.radius, w.length, 24, 1, true).rotateX(Math.PI / 2);
    else if (w.type === "sphere") geo = new THREE.SphereGeometry(w.radius, 24, 16);
    else if (w.type === "ellipsoid") geo = new THREE.SphereGeometry(1, 24, 16).scale(w.dimensions[0], w.dimensions[1], w.dimensions[2]);
    else geo = new THREE.TorusGeometry(w.outer_radius, w.inner_radius, 12, 32);
    const mesh = new THREE.Mesh(geo, wrapMaterial);
    setPose(mesh, w.pose);
    (w.body >= 0 ? bodies[w.body] : scene).add(mesh);
    status.wrap_surfaces++;
  });

  // muscles: a line through the drawn path, markers at path (0), moving/conditional (1) and
  // tangent (2) points, mass points as spheres whose volume is proportional to their mass
  const kindColour = [new THREE.Color(0xffffff), new THREE.Color(0x66dd66), new THREE.Color(0x6fa8dc)];
  const maxPoints = V.muscles.map((_, k) => Math.max(...V.frames.map((f) => f.paths[k].x.length / 3)));
  let heaviest = 0;
  V.muscles.forEach((m) => m.point_masses.forEach((x) => { heaviest = Math.max(heaviest, x); }));
  const sphere = new THREE.SphereGeometry(1, 10, 8);
  const muscles = V.muscles.map((m, k) => {
    const line = new THREE.Line(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0xd04040 }));
    line.geometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(3 * maxPoints[k]), 3));
    const markers = new THREE.Points(new THREE.BufferGeometry(),
                                     new THREE.PointsMaterial({ size: 0.012 * size, vertexColors: true }));
    markers.geometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(3 * maxPoints[k]), 3));
    markers.geometry.setAttribute("color", new THREE.BufferAttribute(new Float32Array(3 * maxPoints[k]), 3));
    const mass = new THREE.InstancedMesh(sphere, new THREE.MeshLambertMaterial({ color: 0xff9933 }), Math.max(m.mass_points, 1));
    mass.count = m.mass_points;
    const group = new THREE.Group();
    group.add(line, markers, mass);
    scene.add(group);
    status.muscles.push(m.name);
    status.mass_points += m.mass_points;
    return { data: m, line, markers, mass, group };
  });

  const scratch = new THREE.Matrix4(), unitQ = new THREE.Quaternion(), at = new THREE.Vector3(), scale = new THREE.Vector3();
  let frame = 0, selected = -1, shown = V.frames[0];

  // the state at time t: between two frames, body poses are slerped and positions, mass points
  // and lengths interpolated linearly; a path whose points changed in number or kind between the
  // two frames (a wrap that engaged, a conditional point) is drawn as the nearer frame's
  function stateAt(t) {
    const T = V.times, n = T.length;
    if (!(t > T[0]) || n === 1) return { F: V.frames[0], f: 0, t: T[0], between: [0, 0] };
    if (t >= T[n - 1]) return { F: V.frames[n - 1], f: n - 1, t: T[n - 1], between: [n - 1, n - 1] };
    let lo = 0, hi = n - 1;
    while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (T[mid] <= t) lo = mid; else hi = mid; }
    const w = T[hi] > T[lo] ? (t - T[lo]) / (T[hi] - T[lo]) : 0;
    const near = w < 0.5 ? lo : hi;
    if (w === 0) return { F: V.frames[lo], f: lo, t, between: [lo, lo] };
    const A = V.frames[lo], B = V.frames[hi];
    const mix = (a, b) => a.map((x, i) => x + w * (b[i] - x));
    const bodies = mix(A.bodies, B.bodies), qa = new THREE.Quaternion(), qb = new THREE.Quaternion();
    for (let b = 0; 7 * b < bodies.length; b++) {
      qa.fromArray(A.bodies, 7 * b + 3).slerp(qb.fromArray(B.bodies, 7 * b + 3), w).toArray(bodies, 7 * b + 3);
    }
    const paths = A.paths.map((pa, k) => {
      const pb = B.paths[k];
      const same = pa.kind.length === pb.kind.length && pa.kind.every((x, i) => x === pb.kind[i]);
      return same ? { x: mix(pa.x, pb.x), kind: pa.kind } : V.frames[near].paths[k];
    });
    const F = { bodies, paths, mass_points: A.mass_points.map((x, k) => mix(x, B.mass_points[k])),
                lengths: mix(A.lengths, B.lengths) };
    return { F, f: near, t, between: [lo, hi] };
  }

  const show = (f) => showTime(V.times[f]);
  function showTime(time) {
    const S = stateAt(time), F = S.F;
    frame = S.f;
    shown = F;
    bodies.forEach((g, b) => setPose(g, F.bodies.slice(7 * b, 7 * b + 7)));
    muscles.forEach((mu, k) => {
      const p = F.paths[k], n = p.x.length / 3;
      mu.line.geometry.attributes.position.array.set(p.x);
      mu.line.geometry.attributes.position.needsUpdate = true;
      mu.line.geometry.setDrawRange(0, n);
      // markers: only the points that are not arc samples
      const pos = mu.markers.geometry.attributes.position, col = mu.markers.geometry.attributes.color;
      let m = 0;
      for (let i = 0; i < n; i++) {
        if (p.kind[i] > 2) continue;
        pos.setXYZ(m, p.x[3 * i], p.x[3 * i + 1], p.x[3 * i + 2]);
        col.setXYZ(m, kindColour[p.kind[i]].r, kindColour[p.kind[i]].g, kindColour[p.kind[i]].b);
        m++;
      }
      pos.needsUpdate = col.needsUpdate = true;
      mu.markers.geometry.setDrawRange(0, m);
      const x = F.mass_points[k];
      for (let i = 0; i < mu.data.mass_points; i++) {
        const r = 0.008 * size * Math.cbrt(mu.data.point_masses[i] / heaviest);
        scratch.compose(at.fromArray(x, 3 * i), unitQ, scale.set(r, r, r));
        mu.mass.setMatrixAt(i, scratch);
      }
      mu.mass.instanceMatrix.needsUpdate = true;
    });
    status.frame = S.f;
    status.between = S.between;
    status.t = S.t;
    status.lengths = F.lengths;
    $("slider").value = S.f;
    $("time").textContent = "t = " + S.t.toFixed(3) + " s";
    readout();
    render();
  }

  function readout() {
    if (selected < 0) return;
    const m = V.muscles[selected];
    let text = m.name + " (" + m.class + ", Type " + m.path_type + ")\n" +
               "length " + shown.lengths[selected].toFixed(5) + " m\n" +
               "mass " + m.mass.toPrecision(4) + " kg in " + m.mass_points + " points";
    if (m.lumped_why) text += "\nno mass points: " + m.lumped_why;
    $("readout").textContent = text;
  }

  function select(k) {
    selected = k;
    muscles.forEach((mu, j) => mu.line.material.color.set(j === k ? 0xffee44 : 0xd04040));
    document.querySelectorAll("#muscles label").forEach((l, j) => l.classList.toggle("selected", j === k));
    readout();
    render();
  }

  V.muscles.forEach((m, k) => {
    const label = document.createElement("label");
    const box = document.createElement("input");
    box.type = "checkbox";
    box.checked = true;
    box.addEventListener("change", () => { muscles[k].group.visible = box.checked; render(); });
    const name = document.createElement("span");
    name.textContent = " " + m.name;
    name.addEventListener("click", (e) => { e.preventDefault(); select(k); });
    label.append(box, name);
    $("muscles").appendChild(label);
  });

  // camera: orbit about the model's centre, looking along -z (OpenSim's sagittal view) when az = 0
  const camera = new THREE.PerspectiveCamera(35, 1, size / 1000, size * 100);
  const orbit = { az: 0.35, el: 0.2, dist: 1.8 * size };
  function render() {
    centre.fromArray(shown.bodies, 0).add(centreOffset);
    camera.position.set(centre.x + orbit.dist * Math.cos(orbit.el) * Math.sin(orbit.az),
                        centre.y + orbit.dist * Math.sin(orbit.el),
                        centre.z + orbit.dist * Math.cos(orbit.el) * Math.cos(orbit.az));
    camera.lookAt(centre);
    renderer.render(scene, camera);
  }
  function resize() {
    const host = $("scene");
    renderer.setSize(host.clientWidth, host.clientHeight);
    camera.aspect = host.clientWidth / Math.max(host.clientHeight, 1);
    camera.updateProjectionMatrix();
    render();
  }
  let drag = null;
  renderer.domElement.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY]; });
  window.addEventListener("pointerup", () => { drag = null; });
  window.addEventListener("pointermove", (e) => {
    if (!drag) return;
    orbit.az -= 0.01 * (e.clientX - drag[0]);
    orbit.el = Math.max(-1.5, Math.min(1.5, orbit.el + 0.01 * (e.clientY - drag[1])));
    drag = [e.clientX, e.clientY];
    render();
  });
  renderer.domElement.addEventListener("wheel", (e) => { e.preventDefault(); orbit.dist *= e.deltaY > 0 ? 1.1 : 1 / 1.1; render(); });
  window.addEventListener("resize", resize);

  // time: #t=SECONDS in the URL shows the state at that time (#t=0.2&muscle=NAME)
  function fromHash() {
    const m = /t=([-+0-9.eE]+)/.exec(location.hash);
    const t = m ? parseFloat(m[1]) : NaN;
    return Number.isFinite(t) ? t : V.times[0];
  }
  // #muscle=NAME selects a muscle (its readout), as a click on its name does
  function selectFromHash() {
    const m = /muscle=([^&]+)/.exec(location.hash);
    const k = m ? V.muscles.findIndex((x) => x.name === decodeURIComponent(m[1])) : -1;
    if (k >= 0) select(k);
  }
  window.addEventListener("hashchange", () => { selectFromHash(); showTime(fromHash()); });
  $("slider").max = V.times.length - 1;
  $("slider").addEventListener("input", (e) => show(parseInt(e.target.value, 10)));
  let playing = null;
  $("play").addEventListener("click", () => {
    if (playing) { cancelAnimationFrame(playing.id); playing = null; $("play").textContent = "play"; return; }
    const t0 = status.t - V.times[0], wall0 = performance.now(), span = V.times[V.times.length - 1] - V.times[0];
    playing = {};
    $("play").textContent = "pause";
    const step = () => {
      const t = span > 0 ? (t0 + (performance.now() - wall0) / 1000) % span : 0;
      showTime(V.times[0] + t);
      playing.id = requestAnimationFrame(step);
    };
    step();
  });

  resize();
  selectFromHash();
  showTime(fromHash());
  status.ready = true;
  // from navigation start (three.min.js and data.js parsed) and in this script, to the first frame
  status.load_ms = Math.round(performance.now());
  status.draw_ms = Math.round(performance.now() - started);
  publish();
})();

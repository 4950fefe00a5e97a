// kerf's 3D view: the scene of <script id="kerf-scene"> drawn with three.js (the global THREE).
// Set-ups are drawn one at a time, each in its own workpiece frame (Z up).
(function () {
  "use strict";
  const errors = [];
  window.addEventListener("error", (e) => errors.push(String(e.message || e)));
  const consoleError = console.error.bind(console);
  console.error = (...a) => { errors.push(a.map(String).join(" ")); consoleError(...a); };

  const data = JSON.parse(document.getElementById("kerf-scene").textContent);
  const SAMPLE = 13;
  const el = (id) => document.getElementById(id);
  const view = el("view");

  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  view.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1e2228);
  const camera = new THREE.PerspectiveCamera(40, 1, 0.1, 1e6);
  camera.up.set(0, 0, 1);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  scene.add(new THREE.AmbientLight(0xffffff, 0.55));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  sun.position.set(1, -1.5, 2);
  scene.add(sun);
  const sun2 = new THREE.DirectionalLight(0xffffff, 0.5);
  sun2.position.set(-1, 1, -1);
  scene.add(sun2);

  // Red (crawling) through yellow (half the feed) to green (at the feed); blue on traverses.
  function speedColour(share, rapid) {
    if (rapid) return [0.27, 0.53, 1.0];
    const s = Math.max(0, Math.min(1, share));
    return s < 0.5 ? [0.9, 0.2 + 1.2 * s, 0.2] : [0.9 - 1.4 * (s - 0.5), 0.8, 0.2 + 0.2 * (s - 0.5)];
  }

  function lines(flat, colour, dashed) {
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.Float32BufferAttribute(flat, 3));
    const m = dashed
      ? new THREE.LineDashedMaterial({ color: colour, dashSize: 4, gapSize: 3 })
      : new THREE.LineBasicMaterial({ color: colour });
    const l = new THREE.Line(g, m);
    if (dashed) l.computeLineDistances();
    return l;
  }

  // Each cut's points split at the points nearest to where its lead-in ends and its lead-out
  // starts (mm along it); the point at a split belongs to both pieces, so none goes missing.
  function cutPieces(c) {
    const p = c.points, n = p.length / 3;
    const along = [0];
    for (let i = 1; i < n; i++) {
      along.push(along[i - 1] + Math.hypot(p[3 * i] - p[3 * i - 3], p[3 * i + 1] - p[3 * i - 2], p[3 * i + 2] - p[3 * i - 1]));
    }
    const total = along[n - 1] || 0;
    const nearest = (s) => {
      let best = 0;
      for (let i = 1; i < n; i++) if (Math.abs(along[i] - s) < Math.abs(along[best] - s)) best = i;
      return best;
    };
    const a = c.lead_in_mm > 0 ? nearest(c.lead_in_mm) : 0;
    const b = c.lead_out_mm > 0 ? Math.max(a, nearest(total - c.lead_out_mm)) : n - 1;
    const piece = (i, j) => (j > i ? p.slice(3 * i, 3 * j + 3) : []);
    return { leadIn: piece(0, a), contour: piece(a, b), leadOut: piece(b, n - 1) };
  }

  const groups = [];
  const drawn = { pierces: 0, markers: 0 };
  const labels = [];
  const markers = [];
  data.setups.forEach((s, k) => {
    const g = new THREE.Group();
    const box = new THREE.Box3();
    for (const surf of s.surfaces) {
      const geom = new THREE.BufferGeometry();
      geom.setAttribute("position", new THREE.Float32BufferAttribute(surf.positions, 3));
      geom.setIndex(surf.indices);
      geom.computeVertexNormals();
      const mesh = new THREE.Mesh(geom, new THREE.MeshStandardMaterial({
        color: 0x9aa4b1, metalness: 0.2, roughness: 0.7, side: THREE.DoubleSide,
        transparent: true, opacity: 0.85, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
      }));
      g.add(mesh);
      geom.computeBoundingBox();
      box.union(geom.boundingBox);
    }
    const beams = [];
    // Beam directions a fiftieth of the part's size long (the surfaces' box, else the paths').
    const extent = new THREE.Box3();
    for (const surf of s.surfaces) for (let j = 0; j + 2 < surf.positions.length; j += 3) extent.expandByPoint(new THREE.Vector3(surf.positions[j], surf.positions[j + 1], surf.positions[j + 2]));
    for (const c of s.cuts) for (let j = 0; j + 2 < c.points.length; j += 3) extent.expandByPoint(new THREE.Vector3(c.points[j], c.points[j + 1], c.points[j + 2]));
    const beamLength = extent.isEmpty() ? 5 : Math.max(1, extent.getSize(new THREE.Vector3()).length() / 50);
    s.cuts.forEach((c, i) => {
      const pieces = cutPieces(c);
      if (pieces.leadIn.length) g.add(lines(pieces.leadIn, 0xd070ff, false));
      if (pieces.contour.length) g.add(lines(pieces.contour, 0xffffff, false));
      if (pieces.leadOut.length) g.add(lines(pieces.leadOut, 0xff9040, false));
      for (let j = 0; j + 5 < c.beams.length; j += 6) {
        const b = c.beams;
        beams.push(b[j], b[j + 1], b[j + 2], b[j] + beamLength * b[j + 3], b[j + 1] + beamLength * b[j + 4], b[j + 2] + beamLength * b[j + 5]);
      }
      const dot = new THREE.Mesh(new THREE.SphereGeometry(0.8, 10, 8), new THREE.MeshBasicMaterial({ color: 0xffd040 }));
      dot.position.set(c.pierce[0], c.pierce[1], c.pierce[2]);
      g.add(dot);
      drawn.pierces += 1;
      labels.push({ setup: k, text: String(i + 1), at: new THREE.Vector3(c.pierce[0], c.pierce[1], c.pierce[2]) });
      for (let j = 0; j < c.points.length; j += 3) box.expandByPoint(new THREE.Vector3(c.points[j], c.points[j + 1], c.points[j + 2]));
    });
    if (beams.length) {
      const bg = new THREE.BufferGeometry();
      bg.setAttribute("position", new THREE.Float32BufferAttribute(beams, 3));
      g.add(new THREE.LineSegments(bg, new THREE.LineBasicMaterial({ color: 0x7fd8ff, transparent: true, opacity: 0.45 })));
    }
    for (const t of s.traverses) g.add(lines(t, 0x4488ff, true));
    // The planned motion coloured by speed.
    const tl = s.timeline.samples, n = tl.length / SAMPLE;
    if (n > 1) {
      const pos = [], col = [];
      for (let i = 0; i < n; i++) {
        pos.push(tl[SAMPLE * i], tl[SAMPLE * i + 1], tl[SAMPLE * i + 2]);
        col.push(...speedColour(tl[SAMPLE * i + 6], tl[SAMPLE * i + 7] > 0.5));
      }
      const mg = new THREE.BufferGeometry();
      mg.setAttribute("position", new THREE.Float32BufferAttribute(pos, 3));
      mg.setAttribute("color", new THREE.Float32BufferAttribute(col, 3));
      g.add(new THREE.Line(mg, new THREE.LineBasicMaterial({ vertexColors: true })));
    }
    g.userData.box = box;
    g.visible = k === 0;
    scene.add(g);
    groups.push(g);
  });

  // Warnings: every one listed; a marker at the point one names where there is one set-up
  // (a warning's text does not say in which set-up's frame its point is).
  const list = el("warnings");
  data.warnings.forEach((w, i) => {
    const li = document.createElement("li");
    li.textContent = w.text.length > 90 ? w.text.slice(0, 90) + "..." : w.text;
    li.onclick = () => showWarning(i);
    list.appendChild(li);
    if (w.point && data.setups.length === 1) {
      const m = new THREE.Mesh(new THREE.OctahedronGeometry(2.5), new THREE.MeshBasicMaterial({ color: 0xff3030 }));
      m.position.set(w.point[0], w.point[1], w.point[2]);
      m.userData.warning = i;
      if (groups[0]) groups[0].add(m);
      markers.push(m);
      drawn.markers += 1;
    }
  });
  function showWarning(i) {
    [...list.children].forEach((li, j) => li.classList.toggle("sel", j === i));
    el("warning-text").textContent = data.warnings[i].text;
  }
  const ray = new THREE.Raycaster();
  renderer.domElement.addEventListener("click", (e) => {
    const r = renderer.domElement.getBoundingClientRect();
    ray.setFromCamera(new THREE.Vector2(((e.clientX - r.left) / r.width) * 2 - 1, -((e.clientY - r.top) / r.height) * 2 + 1), camera);
    const hit = ray.intersectObjects(markers.filter((m) => m.parent && m.parent.visible))[0];
    if (hit) showWarning(hit.object.userData.warning);
  });

  // The head: its solids along the tool axis from the nozzle tip.
  const head = new THREE.Group();
  // The nozzle tip stands `head_standoff_mm` above the tool tip, along the axis.
  let z = data.head_standoff_mm || 0;
  for (const [len, bottom, top] of data.head) {
    const c = new THREE.Mesh(new THREE.CylinderGeometry(top / 2, bottom / 2, len, 32, 1),
      new THREE.MeshStandardMaterial({ color: 0xc8a060, transparent: true, opacity: 0.4, metalness: 0.3, roughness: 0.5, depthWrite: false }));
    c.position.y = z + len / 2;
    head.add(c);
    z += len;
  }
  const headFrame = new THREE.Group();
  headFrame.add(head);
  scene.add(headFrame);

  let setup = 0;
  let time = 0;
  const state = { tip: [0, 0, 0], axis: [0, 0, 1], speed: 0, rapid: false, axes: [0, 0, 0, 0, 0] };

  // The head at time t of set-up k: linear between the two samples around t.
  function setTime(k, t) {
    const s = data.setups[k];
    if (!s) return null;
    const tl = s.timeline, n = tl.samples.length / SAMPLE;
    if (n === 0) return null;
    t = Math.max(0, Math.min(tl.duration_s, t));
    const x = tl.step_s > 0 ? t / tl.step_s : 0;
    const i = Math.min(n - 1, Math.floor(x)), j = Math.min(n - 1, i + 1), f = Math.min(1, x - i);
    const at = (q) => tl.samples[SAMPLE * i + q] * (1 - f) + tl.samples[SAMPLE * j + q] * f;
    const tip = [at(0), at(1), at(2)];
    const ax = new THREE.Vector3(at(3), at(4), at(5)).normalize();
    headFrame.position.set(tip[0], tip[1], tip[2]);
    headFrame.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), ax);
    state.tip = tip;
    state.axis = [ax.x, ax.y, ax.z];
    state.speed = tl.samples[SAMPLE * i + 6] * data.feed_mm_per_min;
    state.rapid = tl.samples[SAMPLE * i + 7] > 0.5;
    state.axes = [8, 9, 10, 11, 12].map(at);
    time = t;
    el("time").value = String(t);
    const names = data.axis_names.length === 5 ? data.axis_names : ["X", "Y", "Z", "A", "C"];
    el("readout").textContent = "t " + t.toFixed(3) + " s of " + tl.duration_s.toFixed(2) +
      " s, " + (state.rapid ? "traverse" : "cut") + " at " + state.speed.toFixed(0) + " mm/min; " +
      state.axes.map((v, k) => names[k] + " " + v.toFixed(3)).join(" ") + "; tip (" +
      tip.map((v) => v.toFixed(2)).join(", ") + ")";
    return { tip: state.tip, axis: state.axis };
  }

  function showSetup(k) {
    setup = k;
    groups.forEach((g, j) => { g.visible = j === k; });
    const tl = data.setups[k].timeline;
    el("time").max = String(tl.duration_s);
    frame(groups[k].userData.box);
    setTime(k, 0);
  }

  function frame(box) {
    if (box.isEmpty()) return;
    const c = box.getCenter(new THREE.Vector3());
    const r = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1);
    controls.target.copy(c);
    camera.position.copy(c).add(new THREE.Vector3(1, -1.4, 1.1).normalize().multiplyScalar(r * 2.6));
    camera.near = r / 100;
    camera.far = r * 100;
    camera.updateProjectionMatrix();
    controls.update();
  }

  const counts = {
    setups: data.setups.length,
    paths: data.setups.reduce((a, s) => a + s.cuts.length, 0),
    pierces: drawn.pierces,
    warning_markers: drawn.markers,
    traverses: data.setups.reduce((a, s) => a + s.traverses.length, 0),
    warnings: data.warnings.length,
    surfaces: data.setups.reduce((a, s) => a + s.surfaces.length, 0),
  };
  el("title").textContent = data.title + " on " + data.machine;
  el("counts").textContent = counts.paths + " cuts, " + counts.pierces + " pierces, " + counts.traverses +
    " traverses, " + counts.warnings + " warnings, " + counts.surfaces + " surfaces";
  const sel = el("setup");
  data.setups.forEach((s, k) => {
    const o = document.createElement("option");
    o.value = String(k);
    o.textContent = (k + 1) + ": " + s.program;
    sel.appendChild(o);
  });
  sel.onchange = () => showSetup(Number(sel.value));
  el("time").oninput = () => setTime(setup, Number(el("time").value));
  let playing = false, last = 0;
  el("play").onclick = () => {
    playing = !playing;
    el("play").textContent = playing ? "pause" : "play";
    last = performance.now();
  };

  const labelLayer = document.createElement("div");
  view.appendChild(labelLayer);
  const labelEls = labels.slice(0, 500).map((l) => {
    const d = document.createElement("div");
    d.className = "lbl";
    d.textContent = l.text;
    labelLayer.appendChild(d);
    return d;
  });

  function resize() {
    const w = view.clientWidth || 800, h = view.clientHeight || 600;
    renderer.setSize(w, h);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  }
  window.addEventListener("resize", resize);

  function render() {
    renderer.render(scene, camera);
    const w = view.clientWidth, h = view.clientHeight;
    labelEls.forEach((d, i) => {
      const l = labels[i];
      const p = l.at.clone().project(camera);
      const show = l.setup === setup && p.z < 1;
      d.style.display = show ? "block" : "none";
      if (show) {
        d.style.left = ((p.x + 1) / 2) * w + 4 + "px";
        d.style.top = ((1 - p.y) / 2) * h - 14 + "px";
      }
    });
  }

  function loop(now) {
    if (playing) {
      const tl = data.setups[setup].timeline;
      let t = time + (now - last) / 1000;
      if (t > tl.duration_s) { t = tl.duration_s; playing = false; el("play").textContent = "play"; }
      setTime(setup, t);
    }
    last = now;
    controls.update();
    render();
    requestAnimationFrame(loop);
  }

  resize();
  if (data.setups.length) showSetup(0);
  render();
  window.kerfView = { counts, setTime, errors, state };

  // Tests: `#t=<seconds>&setup=<k>` writes what the page shows at that time.
  const hash = new URLSearchParams(location.hash.slice(1));
  if (hash.has("t")) {
    const k = Number(hash.get("setup") || 0);
    if (k !== 0 && data.setups[k]) {
      sel.value = String(k);
      sel.dispatchEvent(new Event("change"));
    }
    // Through the slider, as a user moves it.
    const slider = el("time");
    slider.value = hash.get("t");
    slider.dispatchEvent(new Event("input"));
    render();
    const at = { tip: state.tip, axis: state.axis, axes: state.axes, t: time, setup };
    el("kerf-test").textContent = JSON.stringify({ counts, at, errors });
  }
  requestAnimationFrame(loop);
})();

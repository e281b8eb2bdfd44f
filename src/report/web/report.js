// The 3D replay of the HTML report (tubeplan evaluate --html): the scene's parts and the tube's
// deformed centreline per frame (recorded from the judged replay, 20 ms apart or wider for a long
// one, and at its largest force), with the contact points and forces, animated with
// play/pause/scrub. three.js (window.THREE) is embedded before this script. World frame: z up,
// millimetres. A plan's arrays can be long: they are walked with loops, never spread into a
// call's arguments (the engine's argument limit is far below a long recording's frames).
'use strict';
(() => {
  const data = JSON.parse(document.getElementById('tubeplan-data').textContent);
  const canvas = document.getElementById('view');
  const hud = document.getElementById('hud');
  const select = document.getElementById('plan-select');
  const playButton = document.getElementById('play');
  const scrub = document.getElementById('scrub');
  const clock = document.getElementById('clock');
  const speedSelect = document.getElementById('speed');
  let newtonMm = 10;  // arrow length per newton [mm], chosen per plan (niceScale)
  // Triangles of the mesh parts drawn, on the canvas's data-mesh-triangles for the browser test.
  let meshTriangles = 0;

  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xfafbfc);
  const camera = new THREE.PerspectiveCamera(35, 1, 1, 5000);
  camera.up.set(0, 0, 1);
  const controls = new THREE.OrbitControls(camera, canvas);
  controls.enableDamping = false;
  controls.addEventListener('change', () => requestRender());
  scene.add(new THREE.AmbientLight(0xffffff, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  sun.position.set(120, -200, 300);
  scene.add(sun);

  let world = null;    // the current plan's objects
  let dynamic = null;  // what changes per frame
  let plan = null, frame = 0, playing = false, time = 0, lastNow = 0, pending = false;

  function disposeTree(object) {
    object.traverse((o) => {
      if (o.geometry) o.geometry.dispose();
      if (o.material) o.material.dispose();
    });
  }

  // Contacts and forces are drawn over everything: they are often under the tube.
  function onTop(object) {
    object.renderOrder = 10;
    object.traverse((o) => { if (o.material) o.material.depthTest = false; });
    return object;
  }

  function arrow(from, vectorN, colour) {
    const v = new THREE.Vector3(vectorN[0], vectorN[1], vectorN[2]);
    const length = v.length() * newtonMm;
    if (length < 0.5) return null;
    const head = Math.min(6, 0.35 * length);
    return onTop(new THREE.ArrowHelper(v.normalize(), new THREE.Vector3(...from), length, colour,
                                       head, 0.6 * head));
  }

  // Arrow scale: the plan's largest force about 40 mm long, at 1, 2 or 5 times a power of ten.
  function niceScale(p) {
    let largest = 1e-6;
    const take = (f) => { largest = Math.max(largest, Math.hypot(f[0], f[1], f[2])); };
    for (const f of p.frames.force_N) take(f);
    for (const cs of p.frames.contacts) for (const c of cs) { take(c.normal_N); take(c.friction_N); }
    const raw = 40 / largest, magnitude = 10 ** Math.floor(Math.log10(raw));
    return [1, 2, 5, 10].map((m) => m * magnitude).filter((s) => s <= raw).pop();
  }

  // A flat ring closing an end of the hollow tube, facing along `tangent`.
  function endCap(at, tangent, material) {
    const ring = new THREE.Mesh(new THREE.RingGeometry(plan.tube.inner_radius_mm,
                                                       plan.tube.outer_radius_mm, 24), material);
    ring.position.copy(at);
    ring.lookAt(at.clone().add(tangent));
    return ring;
  }

  // A part's surface in its own frame. A cylinder's axis is its frame's z; three.js builds one
  // along y. A mesh part's triangles (data.meshes, written once a page) each get their own
  // normal: its facets are what the contact model sees, and a box's sides stay flat.
  function partGeometry(part) {
    if (part.shape === 'cylinder')
      return new THREE.CylinderGeometry(part.size_mm[0] / 2, part.size_mm[0] / 2, part.size_mm[2], 48)
        .rotateX(Math.PI / 2);
    if (part.shape !== 'mesh') return new THREE.BoxGeometry(...part.size_mm);
    const m = data.meshes[part.mesh];
    const indexed = new THREE.BufferGeometry();
    indexed.setAttribute('position', new THREE.Float32BufferAttribute(m.vertices_mm, 3));
    indexed.setIndex(m.triangles);
    const geometry = indexed.toNonIndexed();
    indexed.dispose();
    geometry.computeVertexNormals();
    meshTriangles += m.triangles.length / 3;
    return geometry;
  }

  // The lines drawn over a part: a mesh's feature edges (where its faces meet, as its elements
  // name them), the edges of a box or a cylinder's rims.
  function partEdges(part, geometry) {
    if (part.shape !== 'mesh') return new THREE.EdgesGeometry(geometry);
    const m = data.meshes[part.mesh];
    const lines = new THREE.BufferGeometry();
    lines.setAttribute('position', new THREE.Float32BufferAttribute(m.vertices_mm, 3));
    lines.setIndex(m.edges);
    return lines;
  }

  function buildWorld(p) {
    if (world) { disposeTree(world); scene.remove(world); }
    world = new THREE.Group();
    meshTriangles = 0;
    const lo = new THREE.Vector3(Infinity, Infinity, Infinity);
    const hi = new THREE.Vector3(-Infinity, -Infinity, -Infinity);
    for (const part of p.parts) {
      const geometry = partGeometry(part);
      const box = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial(
        { color: 0xb9c2cb, transparent: true, opacity: 0.55, depthWrite: false }));
      const [w, x, y, z] = part.q_wxyz;
      box.quaternion.set(x, y, z, w);
      box.position.set(...part.p_mm);
      const edges = new THREE.LineSegments(partEdges(part, geometry),
                                           new THREE.LineBasicMaterial({ color: 0x56606a }));
      edges.quaternion.copy(box.quaternion);
      edges.position.copy(box.position);
      world.add(box, edges);
      // The part's bounding box in its frame (a mesh's need not be centred on it), in world.
      geometry.computeBoundingBox();
      const b = geometry.boundingBox;
      for (const cx of [b.min.x, b.max.x]) for (const cy of [b.min.y, b.max.y]) {
        for (const cz of [b.min.z, b.max.z]) {
          const corner = new THREE.Vector3(cx, cy, cz).applyQuaternion(box.quaternion)
            .add(box.position);
          lo.min(corner); hi.max(corner);
        }
      }
    }
    canvas.dataset.meshTriangles = String(meshTriangles);
    const tubeLo = new THREE.Vector3(Infinity, Infinity, Infinity);
    const tubeHi = new THREE.Vector3(-Infinity, -Infinity, -Infinity);
    for (const c of p.frames.centreline_mm) for (let i = 0; i < c.length; i += 3) {
      tubeLo.min(new THREE.Vector3(c[i], c[i + 1], c[i + 2]));
      tubeHi.max(new THREE.Vector3(c[i], c[i + 1], c[i + 2]));
    }
    for (const h of p.frames.hand_mm) { tubeLo.min(new THREE.Vector3(...h)); tubeHi.max(new THREE.Vector3(...h)); }
    lo.min(tubeLo); hi.max(tubeHi);
    scene.add(world);
    // Aim at where the tube goes, far enough back to see the parts and every pose of the tube,
    // from the front-left and above.
    const centre = tubeLo.clone().add(tubeHi).multiplyScalar(0.5);
    const size = hi.clone().sub(lo).length();
    controls.target.copy(centre);
    camera.position.copy(centre).add(new THREE.Vector3(-0.95, -0.75, 0.75).multiplyScalar(size * 0.7));
    camera.near = size / 100; camera.far = size * 20;
    camera.updateProjectionMatrix();
    controls.update();
  }

  function showFrame(k) {
    const f = plan.frames;
    frame = Math.max(0, Math.min(k, f.t_s.length - 1));
    if (dynamic) { disposeTree(dynamic); scene.remove(dynamic); }
    dynamic = new THREE.Group();
    const c = f.centreline_mm[frame];
    const points = [];
    for (let i = 0; i < c.length; i += 3) points.push(new THREE.Vector3(c[i], c[i + 1], c[i + 2]));
    const curve = new THREE.CatmullRomCurve3(points);
    const material = new THREE.MeshLambertMaterial({ color: data.tube_colour, side: THREE.DoubleSide });
    const tube = new THREE.Mesh(new THREE.TubeGeometry(curve, 64, plan.tube.outer_radius_mm, 24),
                                material);
    tube.name = 'tube';
    dynamic.add(tube, endCap(points[0], curve.getTangent(0), material),
                endCap(points[points.length - 1], curve.getTangent(1), material));
    const held = f.held_mm[frame], hand = f.hand_mm[frame];
    const ball = (p, r, colour) => {
      const m = new THREE.Mesh(new THREE.SphereGeometry(r, 16, 12),
                               new THREE.MeshLambertMaterial({ color: colour }));
      m.position.set(...p);
      return m;
    };
    dynamic.add(ball(hand, 2.5, 0x7a8590));
    const spring = new THREE.BufferGeometry();
    spring.setAttribute('position', new THREE.Float32BufferAttribute([...held, ...hand], 3));
    dynamic.add(new THREE.LineSegments(spring, new THREE.LineBasicMaterial({ color: 0x7a8590 })));
    const operator = arrow(held, f.force_N[frame], 0x222222);
    if (operator) dynamic.add(operator);
    for (const contact of f.contacts[frame]) {
      const dot = onTop(ball(contact.p_mm, 2.2, 0xc8102e));
      if (contact.sliding) { dot.material.transparent = true; dot.material.opacity = 0.45; }
      dynamic.add(dot);
      const normal = arrow(contact.p_mm, contact.normal_N, 0x1f5fd6);
      if (normal) dynamic.add(normal);
      const friction = arrow(contact.p_mm, contact.friction_N, 0xb1008f);
      if (friction) dynamic.add(friction);
    }
    scene.add(dynamic);
    scrub.value = String(frame);
    time = f.t_s[frame];
    clock.textContent = `t = ${time.toFixed(2)} s`;
    const force = f.force_abs_N[frame];
    hud.innerHTML = '';
    const over = force > plan.max_force_N;
    const lines = [[`${plan.name}: ${plan.feasible ? 'FEASIBLE' : 'INFEASIBLE'}`, false],
                   [`CF  ${plan.cfs[f.cf[frame]]}`, false],
                   [`|F| ${force.toFixed(3)} N (limit ${plan.max_force_N} N${over ? ': OVER' : ''})`, over],
                   [`contacts ${f.contacts[frame].length}; arrows ${newtonMm} mm per N`, false]];
    for (const [line, alarm] of lines) {
      const div = document.createElement('div');
      div.textContent = line;
      if (alarm) div.className = 'alarm';
      hud.appendChild(div);
    }
    moveCursors();
    requestRender();
  }

  // A vertical line at the current time on every chart of the plan shown.
  function moveCursors() {
    const index = Number(select.value);
    document.querySelectorAll('section.plan svg[data-x]').forEach((svg) => {
      let line = svg.querySelector('line.cursor');
      const mine = Number(svg.closest('section.plan').dataset.plan) === index;
      if (!mine) { if (line) line.remove(); return; }
      const [lo, hi, pxLo, pxHi] = svg.dataset.x.split(' ').map(Number);
      const x = pxLo + (time - lo) / (hi - lo) * (pxHi - pxLo);
      if (!line) {
        line = document.createElementNS('http://www.w3.org/2000/svg', 'line');
        line.setAttribute('class', 'cursor');
        line.setAttribute('stroke', '#333');
        line.setAttribute('stroke-width', '1');
        svg.appendChild(line);
      }
      const height = svg.viewBox.baseVal.height;
      line.setAttribute('x1', x); line.setAttribute('x2', x);
      line.setAttribute('y1', 30); line.setAttribute('y2', height - 40);
    });
  }

  function frameAt(t) {
    const ts = plan.frames.t_s;
    let lo = 0, hi = ts.length - 1;
    while (lo < hi) { const mid = (lo + hi + 1) >> 1; if (ts[mid] <= t) lo = mid; else hi = mid - 1; }
    return lo;
  }

  function choosePlan(index) {
    plan = data.plans[index];
    select.value = String(index);
    scrub.max = String(plan.frames.t_s.length - 1);
    newtonMm = niceScale(plan);
    buildWorld(plan);
    // Open at the plan's largest force on the operator (the replay's peak tick, which the
    // recording keeps as a frame): where a limit is likeliest crossed.
    showFrame(plan.peak_frame);
  }

  function resize() {
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== Math.round(w * renderer.getPixelRatio()) ||
        canvas.height !== Math.round(h * renderer.getPixelRatio())) {
      renderer.setSize(w, h, false);
      camera.aspect = w / Math.max(h, 1);
      camera.updateProjectionMatrix();
    }
  }

  function requestRender() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(tick);
  }

  function tick(now) {
    pending = false;
    if (playing) {
      const dt = lastNow ? (now - lastNow) / 1000 : 0;
      lastNow = now;
      const ts = plan.frames.t_s;
      const next = time + dt * Number(speedSelect.value);
      if (next >= ts[ts.length - 1]) { setPlaying(false); showFrame(ts.length - 1); }
      else { const k = frameAt(next); if (k !== frame) showFrame(k); time = next; }
    }
    resize();
    renderer.render(scene, camera);
    if (playing) requestRender();
  }

  function setPlaying(on) {
    playing = on;
    lastNow = 0;
    playButton.innerHTML = on ? '&#10074;&#10074; pause' : '&#9654; play';
    if (on) {
      if (frame >= plan.frames.t_s.length - 1) showFrame(0);
      requestRender();
    }
  }

  data.plans.forEach((p, i) => {
    const option = document.createElement('option');
    option.value = String(i);
    option.textContent = `${p.name} (${p.feasible ? 'feasible' : 'infeasible'})`;
    select.appendChild(option);
  });
  select.addEventListener('change', () => { setPlaying(false); choosePlan(Number(select.value)); });
  playButton.addEventListener('click', () => setPlaying(!playing));
  scrub.addEventListener('input', () => { setPlaying(false); showFrame(Number(scrub.value)); });
  window.addEventListener('resize', requestRender);
  // Clicking a chart of a plan shows that plan at that time.
  document.querySelectorAll('section.plan svg[data-x]').forEach((svg) => {
    svg.addEventListener('click', (event) => {
      const index = Number(svg.closest('section.plan').dataset.plan);
      const [lo, hi, pxLo, pxHi] = svg.dataset.x.split(' ').map(Number);
      const box = svg.getBoundingClientRect();
      const px = (event.clientX - box.left) * svg.viewBox.baseVal.width / box.width;
      const t = lo + (px - pxLo) / (pxHi - pxLo) * (hi - lo);
      setPlaying(false);
      if (Number(select.value) !== index) choosePlan(index);
      showFrame(frameAt(Math.max(lo, Math.min(hi, t))));
      document.getElementById('replay').scrollIntoView({ behavior: 'smooth' });
    });
  });
  if (data.plans.length > 0) choosePlan(0);
  document.body.dataset.ready = 'true';
})();

/* fvp trial viewer: draws the embedded scene JSON (format "fvp-viewer-scene", version 1) with
 * three.js r111 (global THREE) and THREE.OrbitControls. User guide and test hook: docs/viewer.md.
 * World frame: metres, z up. Camera frames: OpenCV (x right, y down, z forward). */
(function () {
  'use strict';

  var LAYERS = [ // name, checkbox text; the order of the panel
    ['voxels', 'Fine voxels'], ['mesh', 'TSDF mesh'], ['detections', 'Detections'],
    ['truth', 'Ground truth'], ['region', 'Cluster Region'], ['tag', 'AprilTag'],
    ['cameras', 'Cameras'], ['path', 'Camera path'], ['candidates', 'Chosen candidates']];
  var BACKGROUND = 0x1b1f27; // also viewer.css's body background: a test counts other pixels
  var COL = {
    roi: 0xe8506e, other: 0x7fa36a, mesh: 0xd8c8a4, matched: 0x3ddc84, unmatched: 0xffa23a,
    kept: 0x4aa8ff, dropped: 0x9098a8, truth: 0xffffff, region: 0x8c9bb3, tagFace: 0xcfd4dc,
    tagCode: 0x30343c, reached: 0x3ddc84, missed: 0xff4d4d, seen: 0xffe14d, chosen: 0xffffff, dim: 0x454c59,
    fate_persists: 0x2ca02c, fate_abscises: 0xd62728, fate_gone: 0x7f7f7f, fate_unknown: 0x30343c, fate_unconfirmed: 0xffa23a};
  var FRUSTUM_DEPTH_M = 0.03;

  var diag = window.fvpDiag || { errors: [], warnings: [], blocked: [] };
  var params = new URLSearchParams(location.search);
  var $ = function (id) { return document.getElementById(id); };
  var S = { groups: {}, fit: {}, labels: [], frusta: [], cameraOf: {}, legend: {}, loaded: false };

  // ---------- small helpers ----------
  function vec(a, what) {
    if (!Array.isArray(a) || a.length !== 3 || !a.every(isFinite)) throw new Error(what + ': expected [x, y, z]');
    return new THREE.Vector3(a[0], a[1], a[2]);
  }
  function quat(q, what) { // JSON [w, x, y, z] -> THREE (x, y, z, w)
    if (!Array.isArray(q) || q.length !== 4 || !q.every(isFinite)) throw new Error(what + ': expected [w, x, y, z]');
    return new THREE.Quaternion(q[1], q[2], q[3], q[0]).normalize();
  }
  function bytes(b64, n, what) { // base64 -> ArrayBuffer of exactly n bytes (little-endian data)
    var s = atob(b64 || ''), a = new Uint8Array(s.length);
    for (var i = 0; i < s.length; i++) a[i] = s.charCodeAt(i);
    if (a.length !== n) throw new Error(what + ': ' + a.length + ' bytes, expected ' + n);
    return a.buffer;
  }
  function el(tag, text, cls) {
    var e = document.createElement(tag);
    if (text !== undefined && text !== null) e.textContent = text;
    if (cls) e.className = cls;
    return e;
  }
  function css(hex) { return '#' + ('00000' + hex.toString(16)).slice(-6); }
  function mm(x, digits) { return isFinite(x) ? Number(x).toFixed(digits === undefined ? 2 : digits) + ' mm' : '–'; }
  function lines(points, color, vertexColors) { // LineSegments from [x,y,z, x,y,z, ...]
    var g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(points, 3));
    if (vertexColors) g.setAttribute('color', new THREE.Float32BufferAttribute(vertexColors, 3));
    return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: color, vertexColors: vertexColors ? THREE.VertexColors : THREE.NoColors }));
  }
  function orderColor(i, n) { // capture order: cyan (first) -> violet (last)
    return new THREE.Color().setHSL(0.5 + 0.33 * (n > 1 ? i / (n - 1) : 0), 0.8, 0.6);
  }
  function grow(layer, p, r) { S.fit[layer].push(new THREE.Sphere(p.clone(), r || 0)); } // what framing must show
  function growBox(layer, box) {
    for (var c = 0; c < 8; c++) grow(layer, new THREE.Vector3(c & 1 ? box.max.x : box.min.x, c & 2 ? box.max.y : box.min.y, c & 4 ? box.max.z : box.min.z));
  }
  function addLabel(layer, text, pos, r, color, cls) {
    var e = el('div', text, 'label' + (cls ? ' ' + cls : ''));
    if (color !== undefined) e.style.color = css(color);
    $('labels').appendChild(e);
    S.labels.push({ el: e, layer: layer, pos: pos, r: r });
    return e;
  }

  // ---------- layers ----------
  function buildVoxels(fv, g) {
    var n = fv.count, s = fv.voxel_size_m, o = vec(fv.origin_m, 'fine_voxels.origin_m');
    if (!(n >= 0) || !(s > 0)) throw new Error('fine_voxels: bad count or voxel_size_m');
    var ijk = new Uint16Array(bytes(fv.ijk_u16_b64, 6 * n, 'fine_voxels.ijk_u16_b64'));
    var roi = new Uint8Array(bytes(fv.roi_u8_b64, n, 'fine_voxels.roi_u8_b64'));
    var nroi = 0, i, lo = [65535, 65535, 65535], hi = [0, 0, 0];
    for (i = 0; i < n; i++) nroi += roi[i] ? 1 : 0;
    // One instanced cube mesh per colour: r111's InstancedMesh has no per-instance colour. Each has
    // its own geometry: r111 keeps the bound instance matrices when the next draw shares geometry.
    var fill = [0, 0];
    var meshes = [[n - nroi, COL.other], [nroi, COL.roi]].map(function (c, isRoi) {
      var m = new THREE.InstancedMesh(new THREE.BoxBufferGeometry(s, s, s), new THREE.MeshLambertMaterial({ color: c[1] }), c[0]);
      m.frustumCulled = false; // its bounding sphere would be the one cube's
      m.userData = { kind: 'voxels', roi: isRoi === 1 };
      return m;
    });
    for (i = 0; i < n; i++) {
      var r = roi[i] ? 1 : 0, a = meshes[r].instanceMatrix.array, k = 16 * fill[r]++;
      a[k] = a[k + 5] = a[k + 10] = a[k + 15] = 1; // identity rotation, translation below
      for (var d = 0; d < 3; d++) {
        var v = ijk[3 * i + d];
        a[k + 12 + d] = o.getComponent(d) + (v + 0.5) * s;
        if (v < lo[d]) lo[d] = v;
        if (v > hi[d]) hi[d] = v;
      }
    }
    meshes.forEach(function (m) { if (m.count > 0) g.add(m); });
    if (n > 0) {
      growBox('voxels', new THREE.Box3(new THREE.Vector3().fromArray(lo).multiplyScalar(s).add(o),
        new THREE.Vector3().fromArray(hi).addScalar(1).multiplyScalar(s).add(o)));
    }
    if (nroi) S.legend.roi = 1;
    if (n - nroi) S.legend.other = 1;
  }

  function buildMesh(m, g) {
    var nv = m.vertex_count, nt = m.triangle_count;
    var pos = new Float32Array(bytes(m.vertices_f32_b64, 12 * nv, 'mesh.vertices_f32_b64'));
    var idx = new Uint32Array(bytes(m.triangles_u32_b64, 12 * nt, 'mesh.triangles_u32_b64'));
    for (var i = 0; i < idx.length; i++) if (idx[i] >= nv) throw new Error('mesh: vertex index ' + idx[i] + ' >= ' + nv);
    if (!nt) return;
    var geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    geo.setIndex(new THREE.BufferAttribute(idx, 1));
    geo.computeVertexNormals();
    geo.computeBoundingBox();
    growBox('mesh', geo.boundingBox);
    var mesh = new THREE.Mesh(geo, new THREE.MeshPhongMaterial({ color: COL.mesh, side: THREE.DoubleSide, shininess: 15 }));
    mesh.userData = { kind: 'mesh' };
    g.add(mesh);
    S.legend.mesh = 1;
  }

  function buildDetections(dets, g) {
    var sphere = new THREE.SphereBufferGeometry(1, 32, 16);
    dets.forEach(function (d, i) {
      var c = vec(d.center_m, 'detections[' + i + '].center_m'), r = Math.max(+d.size_mm || 0, 0.2) / 2000;
      // A season's fruitlet (season_viewer.html) is coloured by its predicted fate.
      var status = COL['fate_' + d.fate] !== undefined ? 'fate_' + d.fate :
        !d.kept ? 'dropped' : d.matched === true ? 'matched' : d.matched === false ? 'unmatched' : 'kept';
      var m = new THREE.Mesh(sphere, new THREE.MeshPhongMaterial({
        color: COL[status], transparent: true, opacity: d.kept ? 0.6 : 0.4, depthWrite: false }));
      m.position.copy(c);
      m.scale.setScalar(r);
      g.add(m);
      grow('detections', c, r);
      m.userData = { kind: 'detection', det: d, label: addLabel('detections', (d.label || 'D' + d.id) + ' ' + mm(d.size_mm, 1), c, r, COL[status]) };
      S.legend[status] = 1;
    });
  }

  function buildTruth(gts, dets, g) {
    var sphere = new THREE.SphereBufferGeometry(1, 16, 10), joins = [];
    gts.forEach(function (t, i) {
      var c = vec(t.center_m, 'ground_truth[' + i + '].center_m'), r = Math.max(+t.size_mm || 0, 0.2) / 2000;
      var m = new THREE.Mesh(sphere, new THREE.MeshBasicMaterial({ color: COL.truth, wireframe: true, transparent: true, opacity: 0.7 }));
      m.position.copy(c);
      m.scale.setScalar(r);
      g.add(m);
      grow('truth', c, r);
      m.userData = { kind: 'ground_truth', truth: t, label: addLabel('truth', t.label || 'F' + t.index, c, -r, undefined, 'truth') };
      var d = dets.filter(function (x) { return t.detection !== null && x.id === t.detection; })[0];
      if (d) joins.push.apply(joins, c.toArray().concat(d.center_m)); // error vector truth -> estimate
    });
    if (joins.length) g.add(lines(joins, COL.truth));
    if (gts.length) S.legend.truth = 1;
  }

  function buildRegions(regions, g) {
    regions.forEach(function (reg, i) {
      var c = vec(reg.center_m, 'cluster_regions[' + i + '].center_m'), r = +reg.radius_m;
      if (!(r > 0)) throw new Error('cluster_regions[' + i + '].radius_m: expected > 0');
      var m = new THREE.Mesh(new THREE.SphereBufferGeometry(r, 24, 16),
        new THREE.MeshBasicMaterial({ color: COL.region, wireframe: true, transparent: true, opacity: 0.15 }));
      m.position.copy(c);
      m.userData = { kind: 'cluster_regions' };
      g.add(m);
      grow('region', c, r);
      S.legend.region = 1;
    });
  }

  function buildTags(tags, g) {
    tags.forEach(function (t, i) {
      var s = +t.size_m, tag = new THREE.Group();
      if (!(s > 0)) throw new Error('tags[' + i + '].size_m: expected > 0');
      var face = new THREE.Mesh(new THREE.PlaneBufferGeometry(s, s), new THREE.MeshBasicMaterial({ color: COL.tagFace, side: THREE.DoubleSide }));
      var code = new THREE.Mesh(new THREE.PlaneBufferGeometry(0.6 * s, 0.6 * s), new THREE.MeshBasicMaterial({ color: COL.tagCode, side: THREE.DoubleSide }));
      code.position.z = 0.0005; // just in front of the face, on the +z (outward) side
      tag.add(face, code, new THREE.AxesHelper(0.75 * s)); // x red, y green, z blue
      tag.position.copy(vec(t.position_m, 'tags[' + i + '].position_m'));
      tag.quaternion.copy(quat(t.quaternion_wxyz, 'tags[' + i + '].quaternion_wxyz'));
      tag.userData = { kind: 'tags' };
      g.add(tag);
      grow('tag', tag.position, 0.75 * s);
      S.legend.tag = 1;
    });
  }

  function frustumPoints(K) { // camera-frame line segments: apex to image corners, image border, "up" notch
    K = K || { width_px: 4, height_px: 3, fx_px: 3.46, fy_px: 3.46, cx_px: 2, cy_px: 1.5 }; // ~60 deg if absent
    var D = FRUSTUM_DEPTH_M, c = [[0, 0], [K.width_px, 0], [K.width_px, K.height_px], [0, K.height_px]].map(function (uv) {
      return [(uv[0] - K.cx_px) / K.fx_px * D, (uv[1] - K.cy_px) / K.fy_px * D, D];
    });
    var p = [];
    for (var i = 0; i < 4; i++) p.push.apply(p, [0, 0, 0].concat(c[i], c[i], c[(i + 1) % 4]));
    var w = c[1][0] - c[0][0], top = c[0][1], mid = (c[0][0] + c[1][0]) / 2; // image row 0 is "up" (-y)
    var a = [mid - w / 5, top, D], b = [mid + w / 5, top, D], t = [mid, top - w / 5, D];
    return p.concat(a, t, t, b);
  }

  function buildCameras(cams, K, gFrusta, gPath) {
    var pts = frustumPoints(K), path = [], pathColors = [];
    cams.forEach(function (cam, i) {
      var f = lines(pts, orderColor(i, cams.length));
      f.position.copy(vec(cam.position_m, 'cameras[' + i + '].position_m'));
      f.quaternion.copy(quat(cam.quaternion_wxyz, 'cameras[' + i + '].quaternion_wxyz'));
      f.userData = { kind: 'cameras', cam: cam, color: f.material.color.clone() };
      gFrusta.add(f);
      S.frusta[i] = f;
      S.cameraOf[cam.view === undefined ? i : cam.view] = i; // per_view names views by cameras[].view
      grow('cameras', f.position, FRUSTUM_DEPTH_M * 1.5);
      if (i > 0) { // polyline as segments so each gets the gradient
        path.push.apply(path, S.frusta[i - 1].position.toArray().concat(f.position.toArray()));
        pathColors.push.apply(pathColors, orderColor(i - 1, cams.length).toArray().concat(orderColor(i, cams.length).toArray()));
      }
    });
    if (path.length) {
      gPath.add(lines(path, 0xffffff, pathColors));
      S.fit.path = S.fit.cameras;
    }
    if (cams.length) S.legend.cameras = 1;
  }

  function buildCandidates(cands, g) {
    var marker = new THREE.OctahedronBufferGeometry(0.004);
    cands.forEach(function (cd, i) {
      var col = cd.reached ? COL.reached : COL.missed, m = new THREE.Group();
      m.add(new THREE.Mesh(marker, new THREE.MeshBasicMaterial({ color: col })), lines([0, 0, 0, 0, 0, 0.02], col)); // + viewing direction
      m.position.copy(vec(cd.position_m, 'chosen_candidates[' + i + '].position_m'));
      m.quaternion.copy(quat(cd.quaternion_wxyz, 'chosen_candidates[' + i + '].quaternion_wxyz'));
      m.userData = { kind: 'chosen_candidates', cand: cd };
      g.add(m);
      grow('candidates', m.position, 0.02);
      S.legend[cd.reached ? 'reached' : 'missed'] = 1;
    });
  }

  // ---------- counts, test hook ----------
  function countObjects() { // counts of what is in the three.js scene, not of the JSON
    var c = { fine_voxels: 0, roi_voxels: 0, mesh_triangles: 0, detections: 0, kept_detections: 0, ground_truth: 0,
      cameras: 0, chosen_candidates: 0, tags: 0, cluster_regions: 0 };
    if (S.scene) S.scene.traverse(function (o) {
      var k = o.userData.kind;
      if (k === 'voxels') { c.fine_voxels += o.count; if (o.userData.roi) c.roi_voxels += o.count; }
      else if (k === 'mesh') c.mesh_triangles += o.geometry.index.count / 3;
      else if (k === 'detection') { c.detections++; if (o.userData.det.kept) c.kept_detections++; }
      else if (k) c[k]++;
    });
    return c;
  }
  function shownLayers() { return LAYERS.map(function (l) { return l[0]; }).filter(function (n) { return S.groups[n] && S.groups[n].visible; }); }
  function writeHook() {
    $('fvp-test-hook').textContent = JSON.stringify({ loaded: S.loaded, counts: countObjects(), layers: shownLayers(),
      timing: S.timing, errors: diag.errors, warnings: diag.warnings, blocked: diag.blocked });
  }

  // ---------- view ----------
  function render() {
    S.renderer.render(S.scene, S.camera);
    var w = S.renderer.domElement.clientWidth, h = S.renderer.domElement.clientHeight, up = new THREE.Vector3(0, 1, 0).applyQuaternion(S.camera.quaternion);
    S.labels.forEach(function (l) { // HTML labels over the canvas, just above (or below, r < 0) their sphere
      var p = l.pos.clone().addScaledVector(up, l.r).project(S.camera), show = S.groups[l.layer].visible && p.z < 1 && p.z > -1;
      l.el.style.display = show ? '' : 'none';
      if (show) l.el.style.transform = 'translate(-50%, ' + (l.r < 0 ? '10%' : '-110%') + ') translate(' +
        ((p.x + 1) / 2 * w).toFixed(1) + 'px,' + ((1 - p.y) / 2 * h).toFixed(1) + 'px)';
    });
  }
  function requestRender() { // coalesce control events into one render per frame
    if (S.pending) return;
    S.pending = true;
    requestAnimationFrame(function () { S.pending = false; render(); });
  }
  function centre(names) { // of the bounding box of what the named layers hold (null: nothing)
    var box = new THREE.Box3();
    spheres(names).forEach(function (s) { box.expandByPoint(s.center.clone().addScalar(s.radius)).expandByPoint(s.center.clone().addScalar(-s.radius)); });
    return box.isEmpty() ? null : box.getCenter(new THREE.Vector3());
  }
  function spheres(names) { return [].concat.apply([], names.map(function (n) { return S.fit[n]; })); }
  function frame(names, target) { // deterministic: look at target from viewDir, back off until all fits
    var fit = spheres(names), cam = S.camera;
    if (!fit.length) fit = spheres(LAYERS.map(function (l) { return l[0]; }));
    if (!fit.length) fit = [new THREE.Sphere(new THREE.Vector3(), 0.05)];
    var t = target || centre(names) || fit[0].center;
    cam.position.copy(t).add(S.viewDir);
    cam.lookAt(t);
    cam.updateMatrixWorld();
    var axes = [0, 1, 2].map(function (i) { return new THREE.Vector3().setFromMatrixColumn(cam.matrixWorld, i); });
    var ty = 0.92 * Math.tan(cam.fov / 2 * Math.PI / 180), tx = ty * cam.aspect, dist = 0.01; // 8 % margin
    fit.forEach(function (s) { // its depth towards the viewer plus the distance its offset needs
      var d = s.center.clone().sub(t), x = d.dot(axes[0]), y = d.dot(axes[1]), z = d.dot(axes[2]);
      dist = Math.max(dist, z + s.radius + (Math.abs(x) + s.radius) / tx, z + s.radius + (Math.abs(y) + s.radius) / ty);
    });
    cam.position.copy(t).addScaledVector(S.viewDir, dist);
    cam.near = dist / 1000;
    cam.far = dist * 50;
    cam.updateProjectionMatrix();
    S.controls.target.copy(t);
    S.controls.update();
  }
  function resetView(whole) { // snapshot or whole trial: the shown layers; else the Cluster Region(s)
    if (S.snapshot || whole) return frame(shownLayers(), S.snapshot ? null : S.target);
    frame(S.fit.region.length ? ['region'] : ['voxels', 'mesh', 'detections', 'truth'], S.target);
  }
  function setLayer(name, on) {
    S.groups[name].visible = on;
    if (S.boxes[name]) S.boxes[name].checked = on;
    requestRender();
  }

  // ---------- UI ----------
  function buildPanels(counts, layerOn) {
    var n = { voxels: counts.fine_voxels + ' (' + counts.roi_voxels + ' ROI)', mesh: counts.mesh_triangles + ' tri',
      detections: counts.detections + ' (' + counts.kept_detections + ' kept)', truth: counts.ground_truth,
      region: counts.cluster_regions, tag: counts.tags, cameras: counts.cameras,
      path: Math.max(counts.cameras - 1, 0) + ' seg', candidates: counts.chosen_candidates };
    S.boxes = {};
    LAYERS.forEach(function (l) {
      var box = el('input'), lab = el('label'), empty = S.groups[l[0]].children.length === 0;
      box.type = 'checkbox';
      box.checked = layerOn[l[0]];
      box.disabled = empty;
      box.addEventListener('change', function () { setLayer(l[0], box.checked); });
      lab.append(box, el('span', l[1]), el('span', String(n[l[0]]), 'n'));
      if (empty) lab.className = 'empty';
      $('layers').appendChild(lab);
      S.boxes[l[0]] = box;
    });
    var order = 'cyan → violet';
    [['roi', css(COL.roi), 'ROI voxel (fruitlet)'], ['other', css(COL.other), 'other voxel'], ['mesh', css(COL.mesh), 'TSDF mesh'],
      ['matched', css(COL.matched), 'detection, matched'], ['unmatched', css(COL.unmatched), 'detection, no true fruitlet'],
      ['kept', css(COL.kept), 'detection, kept'], ['dropped', css(COL.dropped), 'detection, dropped'],
      ['fate_persists', css(COL.fate_persists), 'fruitlet, predicted to persist'],
      ['fate_abscises', css(COL.fate_abscises), 'fruitlet, predicted to drop'],
      ['fate_gone', css(COL.fate_gone), 'fruitlet gone (where last seen)'],
      ['fate_unknown', css(COL.fate_unknown), 'fruitlet, fate unknown'],
      ['fate_unconfirmed', css(COL.fate_unconfirmed), 'fruitlet sized once (unconfirmed)'],
      ['truth', css(COL.truth), 'ground truth (wire), line to estimate'], ['region', css(COL.region), 'Cluster Region'],
      ['tag', 'linear-gradient(90deg,#f00 33%,#0f0 33% 66%,#00f 66%)', 'AprilTag, axes x y z'],
      ['cameras', 'linear-gradient(90deg,' + orderColor(0, 2).getStyle() + ',' + orderColor(1, 2).getStyle() + ')', 'view frusta, ' + order],
      ['cameras', css(COL.seen), 'views that saw the selection'], ['reached', css(COL.reached), 'candidate, reached'],
      ['missed', css(COL.missed), 'candidate, not reached']
    ].forEach(function (item) {
      if (!S.legend[item[0]]) return;
      var row = el('div'), sw = el('span', null, 'sw' + (item[1].length > 7 ? ' wide' : ''));
      sw.style.background = item[1];
      row.append(sw, el('span', item[2]));
      $('legend').appendChild(row);
    });
    $('reset').addEventListener('click', function () { resetView(false); requestRender(); });
    $('whole').addEventListener('click', function () { resetView(true); requestRender(); });
  }

  function styleFrusta(seen, chosen) { // null: capture-order colours
    S.frusta.forEach(function (f, i) {
      f.material.color.set(i === chosen ? COL.chosen : !seen ? f.userData.color : seen[i] ? COL.seen : COL.dim);
    });
    requestRender();
  }
  function select(obj) { // a detection or ground-truth sphere (or null) -> side panel
    if (S.selected) S.selected.userData.label.classList.remove('sel');
    S.selected = obj;
    var p = $('panel');
    p.textContent = '';
    if (!obj) { p.hidden = true; styleFrusta(null, -1); return; }
    obj.userData.label.classList.add('sel'); // the sphere itself may hide in its voxels
    var close = el('button', '×', 'close');
    close.addEventListener('click', function () { select(null); });
    var dl = el('dl');
    function row(k, v) { if (v !== undefined && v !== null && v !== '') dl.append(el('dt', k), el('dd', String(v))); }
    p.hidden = false;
    if (obj.userData.kind === 'ground_truth') {
      var t = obj.userData.truth;
      p.append(close, el('h2', 'Ground truth ' + (t.label || t.index)));
      row('size', mm(t.size_mm));
      row('cluster', t.cluster);
      var det = S.groups.detections.children.filter(function (o) { return t.detection !== null && o.userData.det.id === t.detection; })[0];
      row('detection', det ? det.userData.det.label : 'none (missed)');
      p.append(dl);
      if (det) {
        var open = el('button', 'Show ' + det.userData.det.label);
        open.addEventListener('click', function () { select(det); });
        p.append(open);
      }
      styleFrusta(null, -1);
      return requestRender();
    }
    var d = obj.userData.det, s = d.support || {}, gt = (S.data.ground_truth || [])[d.ground_truth];
    p.append(close, el('h2', (d.label || 'D' + d.id) + (d.kept ? '' : ' (dropped)')));
    // The sizer writes -1 for "none" (fewer than two well-seen images, no sphere fit).
    row('size', mm(d.size_mm) + (s.size_stderr_mm >= 0 ? ' ± ' + mm(s.size_stderr_mm) : ''));
    if (d.matched !== undefined) row('ground truth', d.matched && gt ? (gt.label || gt.index) + ', ' + mm(gt.size_mm) : 'not matched');
    if (isFinite(d.error_mm)) row('error (est − true)', mm(d.error_mm));
    row('cluster', d.cluster);
    if (d.fate !== undefined) row('predicted fate', d.fate);
    if (isFinite(d.growth_mm_per_day)) row('growth', mm(d.growth_mm_per_day, 3) + '/day');
    row('sized images', s.sized_images);
    row('well seen images', s.well_seen_images);
    row('sphere fit rms', s.sphere_rms_mm >= 0 ? mm(s.sphere_rms_mm, 3) : 'no sphere fit');
    row('points', s.points === undefined ? undefined : s.points + (isFinite(s.required_points) ? ' (' + Math.ceil(s.required_points) + ' required)' : ''));
    p.append(dl);
    var views = d.per_view || [], seen = {}, table = el('table'), head = el('thead'), body = el('tbody');
    var paper = views.some(function (v) { return isFinite(v.size_paper_mm); }); // optional: the paper's measure too
    head.append(el('tr'));
    head.firstChild.append(el('th', 'view'), el('th', 'size'), paper ? el('th', 'paper') : '', el('th', 'well seen'));
    table.append(head, body);
    var img = el('div');
    views.forEach(function (v) {
      var at = S.cameraOf[v.view];
      if (at !== undefined) seen[at] = true;
      var tr = el('tr');
      tr.append(el('td', v.view), el('td', mm(v.size_mm)), paper ? el('td', mm(v.size_paper_mm)) : '', el('td', v.well_seen ? 'yes' : 'no'));
      tr.addEventListener('click', function () {
        Array.prototype.forEach.call(body.children, function (r) { r.classList.toggle('sel', r === tr); });
        showView(v.view, at, seen, img);
      });
      body.appendChild(tr);
    });
    p.append(el('h2', views.length + ' views saw it'), table, img);
    styleFrusta(seen, -1);
  }
  function showView(view, i, seen, box) { // view: its number; i: its index in cameras (or undefined)
    var cam = (S.data.cameras || [])[i];
    box.textContent = '';
    styleFrusta(seen, i);
    if (!cam) return box.append(el('p', 'view ' + view + ' is not among the cameras', 'muted'));
    setLayer('cameras', true);
    box.append(el('p', ['view ' + view, isFinite(cam.sim_time_s) ? 't = ' + (+cam.sim_time_s).toFixed(1) + ' s' : '',
      cam.tag_detected === undefined ? '' : 'tag ' + (cam.tag_detected ? 'seen' : 'not seen'),
      isFinite(cam.roi_points) ? 'ROI points ' + cam.roi_points + ', other ' + cam.other_points : ''
    ].filter(Boolean).join(', '), 'muted'));
    if (cam.image) {
      var im = el('img');
      im.alt = cam.image;
      im.addEventListener('error', function () { im.replaceWith(el('p', cam.image + ': not found next to the page', 'muted')); });
      im.src = cam.image;
      box.append(im);
    }
  }
  function pick(ev) { // raycast the visible detection and ground-truth spheres
    var rect = S.renderer.domElement.getBoundingClientRect(), ray = new THREE.Raycaster();
    ray.setFromCamera(new THREE.Vector2((ev.clientX - rect.left) / rect.width * 2 - 1, -(ev.clientY - rect.top) / rect.height * 2 + 1), S.camera);
    var targets = [];
    ['detections', 'truth'].forEach(function (n) {
      if (S.groups[n].visible) S.groups[n].children.forEach(function (o) { if (o.isMesh) targets.push(o); });
    });
    var hit = ray.intersectObjects(targets, false)[0];
    if (hit) select(hit.object);
  }

  // ---------- main ----------
  function main() {
    S.t0 = performance.now();
    var node = $('fvp-scene');
    if (!node) throw new Error('no scene: the page has no #fvp-scene element');
    var data = S.data = JSON.parse(node.textContent);
    if (data.format !== 'fvp-viewer-scene' || data.version !== 1)
      throw new Error('scene format ' + data.format + ' version ' + data.version + ': this page reads fvp-viewer-scene version 1');
    document.title = data.title || document.title;
    $('title').textContent = data.title || 'fvp trial';
    $('subtitle').textContent = data.subtitle || '';

    var scene = S.scene = new THREE.Scene();
    scene.background = new THREE.Color(BACKGROUND);
    LAYERS.forEach(function (l) {
      S.groups[l[0]] = new THREE.Group();
      S.groups[l[0]].visible = false; // until the layers are chosen
      S.fit[l[0]] = [];
      scene.add(S.groups[l[0]]);
    });
    var g = S.groups, dets = data.detections || [];
    if (data.fine_voxels) buildVoxels(data.fine_voxels, g.voxels);
    if (data.mesh) buildMesh(data.mesh, g.mesh);
    buildDetections(dets, g.detections);
    buildTruth(data.ground_truth || [], dets, g.truth);
    buildRegions(data.cluster_regions || [], g.region);
    buildTags(data.tags || [], g.tag);
    buildCameras(data.cameras || [], data.intrinsics, g.cameras, g.path);
    buildCandidates(data.chosen_candidates || [], g.candidates);

    // Which layers show: ?layers=a,b (a snapshot: bare page, fitted camera), else all but ground truth,
    // and the mesh only where there are no voxels (the two draw the same surface).
    var want = params.get('layers'), on = {};
    S.snapshot = want !== null;
    if (S.snapshot) {
      want.split(',').filter(Boolean).forEach(function (n) {
        if (!g[n]) throw new Error('unknown layer "' + n + '" in ?layers=; layers: ' + LAYERS.map(function (l) { return l[0]; }).join(','));
        on[n] = true;
      });
      if (params.get('ui') !== '1') document.body.classList.add('snapshot');
    } else {
      LAYERS.forEach(function (l) { on[l[0]] = l[0] !== 'truth' && l[0] !== 'mesh' && g[l[0]].children.length > 0; });
      on.mesh = !on.voxels && g.mesh.children.length > 0;
    }
    LAYERS.forEach(function (l) { g[l[0]].visible = !!on[l[0]]; });

    var renderer = S.renderer = new THREE.WebGLRenderer({ antialias: true });
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setSize(window.innerWidth, window.innerHeight);
    $('view').appendChild(renderer.domElement);
    var camera = S.camera = new THREE.PerspectiveCamera(45, window.innerWidth / window.innerHeight, 0.001, 10);
    camera.up.set(0, 0, 1); // world z up; set before OrbitControls reads it
    scene.add(camera, new THREE.AmbientLight(0xffffff, 0.5));
    var light = new THREE.DirectionalLight(0xffffff, 0.7); // a head light: lit from behind the viewer's shoulder
    light.position.set(0.4, 0.6, 1);
    camera.add(light, light.target);
    S.controls = new THREE.OrbitControls(camera, renderer.domElement);
    S.controls.screenSpacePanning = true;

    // Orbit the Cluster Region's centre (of all regions' box for a tree); look from the side the
    // cameras were on and from 30 degrees above, so the seen side of the cluster faces the viewer.
    S.target = centre(['region']) || centre(['voxels', 'mesh', 'detections', 'truth']) || centre(['cameras']) || new THREE.Vector3();
    var mean = new THREE.Vector3();
    S.frusta.forEach(function (f) { mean.add(f.position); });
    var dir = S.frusta.length ? mean.divideScalar(S.frusta.length).sub(S.target).setZ(0) : new THREE.Vector3();
    if (dir.lengthSq() < 1e-12) dir.set(0, -1, 0);
    S.viewDir = dir.normalize().setZ(Math.tan(Math.PI / 6)).normalize();
    resetView(false);
    S.controls.addEventListener('change', requestRender); // after resetView: the first frame is drawn below

    buildPanels(countObjects(), on);
    window.addEventListener('resize', function () {
      renderer.setSize(window.innerWidth, window.innerHeight);
      camera.aspect = window.innerWidth / window.innerHeight;
      camera.updateProjectionMatrix();
      requestRender();
    });
    var down = null; // a click, not the end of an orbit drag
    renderer.domElement.addEventListener('mousedown', function (e) { down = [e.clientX, e.clientY]; });
    renderer.domElement.addEventListener('click', function (e) {
      if (down && Math.abs(e.clientX - down[0]) + Math.abs(e.clientY - down[1]) < 5) pick(e);
    });
    var sel = params.get('select'); // ?select=D3 (label) or ?select=3 (id)
    if (sel !== null) g.detections.children.forEach(function (o) { if (o.userData.det.label === sel || String(o.userData.det.id) === sel) select(o); });
    var t0 = performance.now();
    render();
    S.timing = { build_ms: Math.round(t0 - S.t0), first_frame_ms: Math.round(performance.now() - t0) };
    S.loaded = true;
  }

  try {
    main();
  } catch (e) {
    diag.errors.push(String(e && e.message || e));
    $('subtitle').textContent = 'This scene cannot be shown: ' + (e && e.message || e);
    $('subtitle').className = 'error';
    document.body.classList.remove('snapshot'); // show the message
  }
  writeHook();
  diag.changed = writeHook; // later errors (e.g. while orbiting) still reach the hook
})();

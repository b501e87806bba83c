(function () {
  "use strict";
  var data = JSON.parse(document.getElementById("rbx-data").textContent);
  var state = {loaded: false, webgl: false, error: "", time: 0, playing: false, backends: {},
               bodies_drawn: 0, frames_shown: {}, ghost: null};
  function publish() { document.getElementById("rbx-state").textContent = JSON.stringify(state); }
  function text(el, s) { el.textContent = s; return el; }
  // Okabe-Ito: colour-blind-safe body colours.
  var bodyColours = [0x0072B2, 0xE69F00, 0x009E73, 0xCC79A7, 0x56B4E9, 0xD55E00, 0xF0E442];
  var names = Object.keys(data.backends);
  var duration = 0;
  names.forEach(function (n) {
    var t = data.backends[n].time || [];
    if (t.length) duration = Math.max(duration, t[t.length - 1]);
    state.backends[n] = {status: data.backends[n].status, frames: t.length,
                         events: (data.backends[n].events || []).length};
  });
  // A measured trajectory drawn as a ghost in every panel (real tosses): its own timeline.
  var ghost = data.ghost || null;
  if (ghost) {
    var gt = ghost.time || [];
    if (gt.length) duration = Math.max(duration, gt[gt.length - 1]);
    state.ghost = {label: ghost.label || "", frames: gt.length, bodies: Object.keys(ghost.frames || {}).length, shown: -1};
  }
  // Scene size from the bodies' vertices at t = 0 and every trajectory point.
  var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  function grow(p) { for (var i = 0; i < 3; ++i) { lo[i] = Math.min(lo[i], p[i]); hi[i] = Math.max(hi[i], p[i]); } }
  var radius = data.shapes.map(function (s) {
    var r = 0; s.vertices.forEach(function (v) { r = Math.max(r, Math.hypot(v[0], v[1], v[2])); }); return r; });
  // The view frames the moving bodies, their trajectories and contacts (and a measured ghost),
  // not the static ones: a floor 40 cube widths wide would leave a small body a few pixels.
  // Only a scene with nothing moving frames its static bodies.
  var anyMoving = data.bodies.some(function (b) { return !b.static; });
  var staticName = {};
  data.bodies.forEach(function (b) { if (b.static && anyMoving) staticName[b.name] = true; });
  if (ghost) Object.keys(ghost.frames || {}).forEach(function (b) { ghost.frames[b].forEach(grow); });
  data.bodies.forEach(function (b) {
    if (staticName[b.name]) return;
    var r = radius[b.shape];
    grow([b.position[0] - r, b.position[1] - r, b.position[2] - r]);
    grow([b.position[0] + r, b.position[1] + r, b.position[2] + r]);
  });
  if (!isFinite(lo[0])) { lo = [-1, -1, -1]; hi = [1, 1, 1]; }
  // Trajectory points widen the view, except those of a run that flew off (an unstable backend
  // 1e6 m away would shrink every panel to a dot): only points within 3 scene sizes count.
  var c0 = [0, 1, 2].map(function (i) { return (lo[i] + hi[i]) / 2; });
  var s0 = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-6);
  names.forEach(function (n) {
    var fr = data.backends[n].frames || {};
    Object.keys(fr).forEach(function (b) { if (staticName[b]) return; fr[b].forEach(function (f) {
      if (Math.hypot(f[0] - c0[0], f[1] - c0[1], f[2] - c0[2]) < 3 * s0) grow(f); }); });
    (data.backends[n].events || []).forEach(function (e) {
      if (Math.hypot(e.point[0] - c0[0], e.point[1] - c0[1], e.point[2] - c0[2]) < 3 * s0) grow(e.point); });
  });
  var centre = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  var size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-6);
  // Arrows scale with the smallest body (a 1000:1 size ratio must still show its normal).
  var rmin = Math.min.apply(null, radius.length ? radius : [size / 2]);
  var arrow = 1.2 * Math.min(size / 2, rmin);
  // A contact query (no timeline): frame the contact region, at the smaller body's scale.
  var cps = (data.reference.contacts || []).slice();
  names.forEach(function (n) { (data.backends[n].events || []).forEach(function (e) { cps.push(e); }); });
  if (data.duration === 0 && cps.length) {
    centre.set(0, 0, 0);
    cps.forEach(function (e) { centre.x += e.point[0] / cps.length; centre.y += e.point[1] / cps.length; centre.z += e.point[2] / cps.length; });
    size = Math.min(size, 3 * rmin);
  }
  state.framed = {size: size, centre: [centre.x, centre.y, centre.z]};

  var canvas = document.getElementById("view");
  var renderer;
  try {
    renderer = new THREE.WebGLRenderer({canvas: canvas, antialias: true, preserveDrawingBuffer: true});
    state.webgl = true;
  } catch (e) {
    // Said on the page, not only in the hidden state: without WebGL nothing else is drawn.
    state.error = "WebGL unavailable: " + e.message;
    var note = text(document.createElement("div"),
      "This page draws every backend's run with WebGL, which this browser did not provide (" +
      e.message + "). Turn on hardware acceleration or WebGL in the browser's settings, or " +
      "open the page in another browser; the numbers are in the report beside it.");
    note.id = "rbx-no-webgl";
    canvas.style.display = "none";
    document.getElementById("stage").appendChild(note);
    publish(); return;
  }
  renderer.setPixelRatio(1);
  renderer.setScissorTest(true);
  var camera = new THREE.PerspectiveCamera(40, 1, size * 1e-3, size * 100);
  var yaw = 0.7, pitch = 0.45, dist = 2.2 * size;
  function placeCamera() {
    camera.position.set(centre.x + dist * Math.cos(pitch) * Math.cos(yaw),
                        centre.y + dist * Math.cos(pitch) * Math.sin(yaw),
                        centre.z + dist * Math.sin(pitch));
    camera.up.set(0, 0, 1); camera.lookAt(centre);
  }
  placeCamera();

  // One three.js scene per backend: bodies, its events, the reference.
  var geoms = data.shapes.map(function (s) {
    var g = new THREE.BufferGeometry(), pos = [];
    s.triangles.forEach(function (t) { t.forEach(function (i) { pos.push(s.vertices[i][0], s.vertices[i][1], s.vertices[i][2]); }); });
    g.setAttribute("position", new THREE.Float32BufferAttribute(pos, 3));
    g.computeVertexNormals();
    return {mesh: g, edges: new THREE.EdgesGeometry(g, 20)};
  });
  var panels = names.map(function (n, k) {
    var sc = new THREE.Scene();
    sc.background = new THREE.Color(0xf7f7f7);
    sc.add(new THREE.AmbientLight(0xffffff, 0.55));
    var light = new THREE.DirectionalLight(0xffffff, 0.6); light.position.set(1, 0.6, 2); sc.add(light);
    var bodies = data.bodies.map(function (b, i) {
      var grp = new THREE.Group();
      var mat = new THREE.MeshLambertMaterial({color: bodyColours[i % bodyColours.length],
        transparent: true, opacity: 0.45, side: THREE.DoubleSide});
      grp.add(new THREE.Mesh(geoms[b.shape].mesh, mat));
      grp.add(new THREE.LineSegments(geoms[b.shape].edges, new THREE.LineBasicMaterial({color: 0x333333})));
      grp.position.set(b.position[0], b.position[1], b.position[2]);
      grp.quaternion.set(b.orientation[1], b.orientation[2], b.orientation[3], b.orientation[0]);
      sc.add(grp); state.bodies_drawn += 1;
      return grp;
    });
    function marker(e, colour) {
      var g = new THREE.Group();
      var dot = new THREE.Mesh(new THREE.SphereBufferGeometry(0.04 * arrow + 1e-9, 10, 8),
                               new THREE.MeshBasicMaterial({color: colour}));
      g.add(dot);
      var n = new THREE.Vector3(e.normal[0], e.normal[1], e.normal[2]);
      if (n.length() > 0.5) {
        // Drawn over the bodies (no depth test): a normal inside a body must still show.
        var a = new THREE.ArrowHelper(n.normalize(), new THREE.Vector3(), arrow, colour, 0.3 * arrow, 0.15 * arrow);
        // In the transparent pass after the bodies, the backend over the reference: a wrong
        // normal shows on top of the right one.
        [a.line, a.cone].forEach(function (o) { o.material.depthTest = false; o.material.transparent = true; o.renderOrder = colour === 0 ? 10 : 11; });
        g.add(a);
      }
      g.position.set(e.point[0], e.point[1], e.point[2]);
      sc.add(g); return g;
    }
    var events = (data.backends[n].events || []).map(function (e) { return {t: e.t, obj: marker(e, 0xd62728)}; });
    var ref = [];
    (data.reference.contacts || []).forEach(function (e) { ref.push({t: e.t, obj: marker(e, 0x000000)}); });
    var finals = data.reference.finals || {};
    var refFinal = [];
    data.bodies.forEach(function (b, i) {
      var v = finals[b.name];
      if (!v || !v.velocity) return;
      var d = new THREE.Vector3(v.velocity[0], v.velocity[1], v.velocity[2]);
      var len = d.length();
      if (len === 0) return;
      var a = new THREE.ArrowHelper(d.normalize(), new THREE.Vector3(), arrow * 2, 0x000000, 0.3 * arrow, 0.15 * arrow);
      sc.add(a); refFinal.push({body: i, obj: a});
    });
    // The ghost: every body it tracks, grey and faint, over the backend's own bodies.
    var ghosts = [];
    if (ghost) data.bodies.forEach(function (b, i) {
      if (!(ghost.frames || {})[b.name]) return;
      var grp = new THREE.Group();
      grp.add(new THREE.Mesh(geoms[b.shape].mesh, new THREE.MeshBasicMaterial({color: 0x000000,
        transparent: true, opacity: 0.18, depthWrite: false, side: THREE.DoubleSide})));
      grp.add(new THREE.LineSegments(geoms[b.shape].edges, new THREE.LineBasicMaterial({color: 0x000000,
        transparent: true, opacity: 0.5})));
      sc.add(grp); ghosts.push({body: b.name, obj: grp});
    });
    var label = document.createElement("div");
    label.className = "label";
    var st = data.backends[n].status;
    text(label, n + (st === "ok" ? "" : " (" + st + ")"));
    label.title = data.backends[n].message || "";
    document.getElementById("labels").appendChild(label);
    return {name: n, scene: sc, bodies: bodies, events: events, ref: ref, refFinal: refFinal,
            ghosts: ghosts, label: label, visible: true};
  });

  // Controls: per-backend toggles, reference toggle, play/pause, slider.
  var toggles = document.getElementById("toggles");
  panels.forEach(function (p) {
    var l = document.createElement("label"), c = document.createElement("input");
    c.type = "checkbox"; c.checked = true;
    c.addEventListener("change", function () { p.visible = c.checked; layout(); render(); });
    l.appendChild(c);
    // The backend's colour, as in the report's figures (in the header, off the drawing).
    var colour = data.backends[p.name].colour;
    if (colour) {
      var sw = document.createElement("span");
      sw.style.cssText = "display:inline-block;width:.8em;height:.8em;margin-left:.3em;background:" + colour;
      l.appendChild(sw);
    }
    l.appendChild(document.createTextNode(" " + p.name)); toggles.appendChild(l);
  });
  var showRef = true;
  var rc = document.getElementById("ref");
  rc.addEventListener("change", function () { showRef = rc.checked; render(); });
  var slider = document.getElementById("slider"), play = document.getElementById("play");
  var clock = document.getElementById("clock");
  slider.addEventListener("input", function () { setTime(duration * slider.value / 1000); });
  play.addEventListener("click", function () { setPlaying(!state.playing); });
  function setPlaying(on) { state.playing = on; text(play, on ? "pause" : "play"); publish(); if (on) tick.last = null, requestAnimationFrame(tick); }

  function frameAt(times, t) {  // last frame at or before t
    var k = 0; while (k + 1 < times.length && times[k + 1] <= t + 1e-12) ++k; return k;
  }
  // The pose at time t between key frames k and k + 1 (results keep key frames only): positions
  // linearly, quaternions by normalised lerp on the short arc, as the frames were thinned.
  function pose(f, times, k, t) {
    var a = f[Math.min(k, f.length - 1)];
    if (k + 1 >= f.length || k + 1 >= times.length || times[k + 1] <= times[k]) return a;
    var b = f[k + 1], u = Math.min(Math.max((t - times[k]) / (times[k + 1] - times[k]), 0), 1);
    var dot = a[3] * b[3] + a[4] * b[4] + a[5] * b[5] + a[6] * b[6], sg = dot < 0 ? -1 : 1;
    var out = [], n = 0, j;
    for (j = 0; j < 3; ++j) out.push(a[j] + (b[j] - a[j]) * u);
    for (j = 3; j < 7; ++j) { out.push(a[j] + (sg * b[j] - a[j]) * u); n += out[j] * out[j]; }
    n = Math.sqrt(n) || 1;
    for (j = 3; j < 7; ++j) out[j] /= n;
    return out;
  }
  function setTime(t) {
    state.time = Math.min(Math.max(t, 0), duration);
    slider.value = duration > 0 ? Math.round(1000 * state.time / duration) : 0;
    text(clock, "t = " + state.time.toFixed(4) + " s / " + duration.toFixed(4) + " s");
    var window = Math.max(duration / 20, 1e-9);
    panels.forEach(function (p) {
      var b = data.backends[p.name], times = b.time || [];
      var k = frameAt(times, state.time);
      state.frames_shown[p.name] = times.length ? k : -1;
      data.bodies.forEach(function (body, i) {
        var f = b.frames && b.frames[body.name];
        if (!f || !f.length) return;
        var s = pose(f, times, k, state.time);
        p.bodies[i].position.set(s[0], s[1], s[2]);
        p.bodies[i].quaternion.set(s[4], s[5], s[6], s[3]);
      });
      // Events near the current time (all of them when the run has no timeline).
      p.events.forEach(function (e) { e.obj.visible = duration === 0 || (e.t <= state.time + 1e-12 && e.t > state.time - window); });
      p.ref.forEach(function (e) { e.obj.visible = showRef; });
      if (ghost) {
        var gk = frameAt(ghost.time || [], state.time);
        state.ghost.shown = gk;
        p.ghosts.forEach(function (g) {
          var f = ghost.frames[g.body], s = f[Math.min(gk, f.length - 1)];
          g.obj.position.set(s[0], s[1], s[2]);
          g.obj.quaternion.set(s[4], s[5], s[6], s[3]);
          g.obj.visible = showRef;
        });
      }
      p.refFinal.forEach(function (r) {
        r.obj.visible = showRef && state.time >= duration - 1e-12;
        r.obj.position.copy(p.bodies[r.body].position);
      });
    });
    render();
  }
  function tick(now) {
    if (!state.playing) return;
    if (tick.last != null) {
      var t = state.time + (duration / 4) * (now - tick.last) / 1000;  // the whole run in 4 s
      if (t >= duration) { setTime(duration); setPlaying(false); return; }
      setTime(t);
    }
    tick.last = now;
    requestAnimationFrame(tick);
  }

  var rects = [];
  function layout() {
    var w = canvas.clientWidth, h = canvas.clientHeight;
    renderer.setSize(w, h, false);
    var shown = panels.filter(function (p) { return p.visible; });
    var cols = Math.ceil(Math.sqrt(shown.length || 1)), rows = Math.ceil((shown.length || 1) / cols);
    var pw = Math.floor(w / cols), ph = Math.floor(h / rows);
    rects = [];
    panels.forEach(function (p) { p.label.style.display = "none"; });
    shown.forEach(function (p, k) {
      var x = (k % cols) * pw, y = Math.floor(k / cols) * ph;
      rects.push({p: p, x: x, y: h - y - ph, w: pw - 2, h: ph - 2});
      p.label.style.display = "block";
      p.label.style.left = (x + 6) + "px"; p.label.style.top = (y + 4) + "px";
    });
    camera.aspect = pw / ph; camera.updateProjectionMatrix();
    state.canvas_top = Math.round(canvas.getBoundingClientRect().top);
  }
  function render() {
    renderer.setClearColor(0xffffff); renderer.setScissor(0, 0, canvas.width, canvas.height); renderer.clear();
    rects.forEach(function (r) {
      renderer.setViewport(r.x, r.y, r.w, r.h); renderer.setScissor(r.x, r.y, r.w, r.h);
      renderer.render(r.p.scene, camera);
    });
    publish();
  }
  // Orbit with the mouse, zoom with the wheel.
  var drag = null;
  canvas.addEventListener("mousedown", function (e) { drag = [e.clientX, e.clientY]; });
  window.addEventListener("mouseup", function () { drag = null; });
  window.addEventListener("mousemove", function (e) {
    if (!drag) return;
    yaw -= (e.clientX - drag[0]) * 0.01; pitch = Math.max(-1.5, Math.min(1.5, pitch + (e.clientY - drag[1]) * 0.01));
    drag = [e.clientX, e.clientY]; placeCamera(); render();
  });
  canvas.addEventListener("wheel", function (e) { e.preventDefault(); dist *= e.deltaY > 0 ? 1.1 : 0.9; placeCamera(); render(); });
  window.addEventListener("resize", function () { layout(); render(); });

  layout();
  // #t=SECONDS opens at that time of the run, as a media fragment does (clamped to the run;
  // #t=end at its end); #play starts playing.
  var hash = window.location.hash, m = /t=(end|[0-9.eE+]+)/.exec(hash);
  var at = m ? (m[1] === "end" ? duration : parseFloat(m[1])) : 0;
  setTime(isFinite(at) ? at : 0);
  state.loaded = true;
  publish();
  if (/play/.test(hash)) setPlaying(true);
})();

/* camfab report: a cylindrical cam's animation (vanilla JS, no network).
 * Reads the precomputed frames of camfab.report.cylinder_animation from <script id="anim-data"> and draws on
 * <canvas id="anim-canvas"> the cylinder seen from the follower's side (axis horizontal), turning: the groove's
 * edges and generator lines turned by the frame's cam angle and shown on the front half, the roller at its exact
 * position along the axis (and the oscillating arm from its pivot), and a strip with S over the cycle.
 * Controls: #anim-play, #anim-speed, #anim-angle.
 */
(function () {
  "use strict";
  var holder = document.getElementById("anim-data");
  var canvas = document.getElementById("anim-canvas");
  if (!holder || !canvas || !canvas.getContext) { return; }
  var D = JSON.parse(holder.textContent);
  var ctx = canvas.getContext("2d");
  var N = D.frames.x.length;
  var playBtn = document.getElementById("anim-play");
  var speed = document.getElementById("anim-speed");
  var speedOut = document.getElementById("anim-speed-value");
  var scrub = document.getElementById("anim-angle");
  var outAngle = document.getElementById("anim-angle-readout");
  var outS = document.getElementById("anim-s-readout");
  var outPa = document.getElementById("anim-pa-readout");
  var COL = { body: "#cfe0f3", bodyLine: "#1f5fa8", groove: "#7d8fa6", mark: "rgba(31,95,168,0.35)",
              mark0: "#d46a00", link: "#555", roller: "#f2c14e", rollerLine: "#7a5a00", guide: "#999",
              grid: "#e6e6e6", text: "#333", strip: "#1f77b4", dot: "#d62728" };
  var pos = 0, playing = true, last = null, W = 0, H = 0, dpr = 1, shown = -1;

  function resize() {
    var w = canvas.clientWidth || 600;
    dpr = window.devicePixelRatio || 1;
    W = w; H = Math.round(w * 0.86);
    canvas.style.height = H + "px";
    canvas.width = Math.round(W * dpr); canvas.height = Math.round(H * dpr);
    shown = -1;
  }

  var view = { s: 1, ox: 0, oy: 0 };
  function fit() {
    var b = D.bounds, vh = H * 0.78 - 10, vw = W - 20;
    var s = Math.min(vw / (b[1] - b[0]), vh / (b[3] - b[2]));
    view.s = s;
    view.ox = 10 + (vw - s * (b[1] - b[0])) / 2 - s * b[0];
    view.oy = 10 + (vh - s * (b[3] - b[2])) / 2 + s * b[3];
  }
  function X(u) { return view.ox + view.s * u; }
  function Y(v) { return view.oy - view.s * v; }
  function line(u1, v1, u2, v2, colour, width, dash) {
    ctx.beginPath(); ctx.moveTo(X(u1), Y(v1)); ctx.lineTo(X(u2), Y(v2));
    ctx.strokeStyle = colour; ctx.lineWidth = width; ctx.setLineDash(dash || []); ctx.stroke(); ctx.setLineDash([]);
  }

  // a cam-frame point (angle a, z) on the cylinder r after the cam turned by theta: [u, v, facing the viewer]
  function project(a, z, r, theta) {
    var alpha = a - D.sense * theta;
    return [z, r * Math.cos(alpha), Math.sin(alpha) > 0];
  }

  function drawCylinder(i) {
    var theta = D.frames.angle[i], L = D.length, ro = D.outer;
    ctx.fillStyle = COL.body; ctx.fillRect(X(0), Y(ro), view.s * L, view.s * 2 * ro);
    D.marks.forEach(function (a, k) {  // generator lines on the front half, the 0° one in orange
      var p = project(a, 0, ro, theta);
      if (!p[2]) { return; }
      line(0, p[1], L, p[1], k === 0 ? COL.mark0 : COL.mark, k === 0 ? 2 : 1);
    });
    D.edges.forEach(function (pts) {
      ctx.beginPath();
      var pen = false;
      for (var j = 0; j < pts.length; j += 2) {
        var p = project(pts[j], pts[j + 1], ro, theta);
        if (!p[2]) { pen = false; continue; }
        if (pen) { ctx.lineTo(X(p[0]), Y(p[1])); } else { ctx.moveTo(X(p[0]), Y(p[1])); pen = true; }
      }
      ctx.strokeStyle = COL.groove; ctx.lineWidth = 2; ctx.stroke();
    });
    ctx.strokeStyle = COL.bodyLine; ctx.lineWidth = 2; ctx.strokeRect(X(0), Y(ro), view.s * L, view.s * 2 * ro);
    line(-0.08 * L, 0, 1.08 * L, 0, "#888", 1, [8, 3, 2, 3]);  // the cam axis
    ctx.fillStyle = COL.text; ctx.font = "12px sans-serif"; ctx.textAlign = "left";
    ctx.fillText("z = 0", X(0), Y(-ro) + 14);
    ctx.fillText((D.sense > 0 ? "cw" : "ccw") + " seen from +z", X(0.55 * L), Y(-ro) + 14);
  }

  function drawFollower(i) {
    var u = D.frames.roller[2 * i], v = D.frames.roller[2 * i + 1], r = D.roller_radius, ro = D.outer;
    if (D.pivot) {
      line(D.pivot[0], D.pivot[1], u, v, COL.link, 5);
      ctx.beginPath(); ctx.arc(X(D.pivot[0]), Y(D.pivot[1]), 6, 0, 2 * Math.PI);
      ctx.fillStyle = "#fff"; ctx.fill(); ctx.strokeStyle = "#333"; ctx.lineWidth = 2; ctx.stroke();
    } else {  // the follower's slide (its stem comes towards the viewer) between two rails parallel to the axis
      var h = 1.35 * r;
      line(-0.1 * D.length, v + h + 1.5 / view.s, 1.1 * D.length, v + h + 1.5 / view.s, COL.guide, 3);
      line(-0.1 * D.length, v - h - 1.5 / view.s, 1.1 * D.length, v - h - 1.5 / view.s, COL.guide, 3);
      ctx.fillStyle = "rgba(120,120,120,0.55)"; ctx.fillRect(X(u - 1.8 * r), Y(v + h), view.s * 3.6 * r, view.s * 2 * h);
    }
    ctx.beginPath(); ctx.arc(X(u), Y(v), Math.max(r * view.s, 2), 0, 2 * Math.PI);
    ctx.fillStyle = COL.roller; ctx.fill(); ctx.strokeStyle = COL.rollerLine; ctx.lineWidth = 1.5; ctx.stroke();
    ctx.beginPath(); ctx.arc(X(u), Y(v), 2.5, 0, 2 * Math.PI); ctx.fillStyle = "#333"; ctx.fill();
  }

  function drawStrip(i) {
    var top = H * 0.8, h = H * 0.17, left = 46, w = W - left - 12, S = D.frames.S;
    var smin = Math.min.apply(null, S), smax = Math.max.apply(null, S);
    if (smax - smin < 1e-9) { smax = smin + 1; }
    function sx(j) { return left + w * j / N; }
    function sy(v) { return top + h - h * (v - smin) / (smax - smin); }
    ctx.strokeStyle = COL.grid; ctx.lineWidth = 1; ctx.strokeRect(left, top, w, h);
    ctx.beginPath();
    for (var j = 0; j <= N; j++) { var v = S[j % N]; if (j === 0) { ctx.moveTo(sx(j), sy(v)); } else { ctx.lineTo(sx(j), sy(v)); } }
    ctx.strokeStyle = COL.strip; ctx.lineWidth = 1.5; ctx.stroke();
    ctx.beginPath(); ctx.moveTo(sx(i), top); ctx.lineTo(sx(i), top + h); ctx.strokeStyle = COL.dot; ctx.stroke();
    ctx.beginPath(); ctx.arc(sx(i), sy(S[i]), 3.5, 0, 2 * Math.PI); ctx.fillStyle = COL.dot; ctx.fill();
    ctx.fillStyle = COL.text; ctx.font = "11px sans-serif";
    ctx.fillText("S (" + D.lift_unit + ")", 4, top + 10);
    ctx.fillText(smax.toFixed(2), 4, top + 24); ctx.fillText(smin.toFixed(2), 4, top + h);
    ctx.fillText("0", left, top + h + 12);
    ctx.textAlign = "right"; ctx.fillText("360°", left + w, top + h + 12); ctx.textAlign = "left";
  }

  function frameIndex() { return Math.floor(pos) % N; }

  function render() {
    var i = frameIndex();
    if (i === shown) { return; }
    shown = i;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, W, H);
    ctx.fillStyle = "#fff"; ctx.fillRect(0, 0, W, H);
    fit();
    ctx.save();
    ctx.beginPath(); ctx.rect(0, 0, W, H * 0.78); ctx.clip();
    drawCylinder(i);
    drawFollower(i);
    ctx.restore();
    drawStrip(i);
    outAngle.textContent = D.frames.x[i].toFixed(1) + "°";
    outS.textContent = D.frames.S[i].toFixed(3) + " " + D.lift_unit;
    var pa = D.frames.pa[0][i], bad = D.pa_limit !== null && Math.abs(pa) > D.pa_limit;
    outPa.textContent = pa.toFixed(2) + "° on the pitch cylinder" + (D.pa_limit !== null ? " (limit ±" + D.pa_limit + "°)" : "");
    outPa.className = bad ? "readout bad" : "readout";
    scrub.value = String(i);
  }

  function tick(t) {
    if (last === null) { last = t; }
    var dt = Math.min((t - last) / 1000, 0.25);
    last = t;
    if (playing) { pos = (pos + dt * Number(speed.value) / 60 * N) % N; }
    render();
    window.requestAnimationFrame(tick);
  }

  function setPlaying(p) {
    playing = p;
    playBtn.textContent = p ? "Pause" : "Play";
    playBtn.setAttribute("aria-pressed", p ? "true" : "false");
  }

  playBtn.addEventListener("click", function () { setPlaying(!playing); });
  speed.addEventListener("input", function () { speedOut.textContent = speed.value; });
  scrub.max = String(N - 1);
  scrub.addEventListener("input", function () { setPlaying(false); pos = Number(scrub.value); render(); });
  window.addEventListener("resize", function () { resize(); render(); });
  speedOut.textContent = speed.value;
  resize();
  setPlaying(true);
  render();
  window.requestAnimationFrame(tick);
  window.camfabAnimation = {
    frame: function () { return frameIndex(); },
    playing: function () { return playing; },
    play: function () { setPlaying(true); },
    pause: function () { setPlaying(false); },
    frames: N
  };
})();

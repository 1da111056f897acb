/* camfab report: mechanism animation (vanilla JS, no network).
 * Reads the precomputed frames of camfab.report.animation from <script id="anim-data">
 * and draws them on <canvas id="anim-canvas">: the cam turning about its centre (or
 * sliding), the follower of the same frame (a curved face as its arc), the contact point with its line of action,
 * and a strip with S against the cam angle.  Controls: #anim-play, #anim-speed, #anim-angle.
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
  var COL = { cam: "#cfe0f3", camLine: "#1f5fa8", cam2: "rgba(255,187,120,0.45)", cam2Line: "#d46a00",
              link: "#555", roller: "#f2c14e", rollerLine: "#7a5a00", face: "#8c564b", contact: "#d62728",
              guide: "#999", grid: "#e6e6e6", text: "#333", strip: "#1f77b4" };
  var pos = 0, playing = true, last = null, W = 0, H = 0, dpr = 1, shown = -1;

  function resize() {
    var w = canvas.clientWidth || 600;
    dpr = window.devicePixelRatio || 1;
    W = w; H = Math.round(w * 0.86);
    canvas.style.height = H + "px";
    canvas.width = Math.round(W * dpr); canvas.height = Math.round(H * dpr);
    shown = -1;
  }

  // world (mm, y up) -> screen, equal scale, mechanism view in the top 78%
  var view = { s: 1, ox: 0, oy: 0 };
  function fit() {
    var b = D.bounds, vh = H * 0.78 - 10, vw = W - 20;
    var s = Math.min(vw / (b[1] - b[0]), vh / (b[3] - b[2]));
    view.s = s;
    view.ox = 10 + (vw - s * (b[1] - b[0])) / 2 - s * b[0];
    view.oy = 10 + (vh - s * (b[3] - b[2])) / 2 + s * b[3];
  }
  function X(x) { return view.ox + view.s * x; }
  function Y(y) { return view.oy - view.s * y; }

  function line(x1, y1, x2, y2, colour, width, dash) {
    ctx.beginPath(); ctx.moveTo(X(x1), Y(y1)); ctx.lineTo(X(x2), Y(y2));
    ctx.strokeStyle = colour; ctx.lineWidth = width; ctx.setLineDash(dash || []); ctx.stroke(); ctx.setLineDash([]);
  }
  function circle(x, y, r, fill, stroke, width, dash) {
    ctx.beginPath(); ctx.arc(X(x), Y(y), Math.max(r * view.s, 1.5), 0, 2 * Math.PI);
    if (fill) { ctx.fillStyle = fill; ctx.fill(); }
    if (stroke) { ctx.strokeStyle = stroke; ctx.lineWidth = width || 1; ctx.setLineDash(dash || []); ctx.stroke(); ctx.setLineDash([]); }
  }

  // a face-groove cam: the plate (a wall of the groove's width round the outer flank), the groove between the
  // flanks, the island inside the inner flank; both flanks solid
  function drawGroove(c, s) {
    [[1, "wall"], [1, "groove"], [0, "island"]].forEach(function (step) {
      var pts = D.outline[step[0]];
      ctx.beginPath();
      for (var j = 0; j < pts.length; j += 2) {
        var u = pts[j] * c - pts[j + 1] * s, v = pts[j] * s + pts[j + 1] * c;
        if (j === 0) { ctx.moveTo(X(u), Y(v)); } else { ctx.lineTo(X(u), Y(v)); }
      }
      ctx.closePath();
      if (step[1] === "wall") {
        ctx.strokeStyle = COL.cam; ctx.lineWidth = 4 * D.groove * view.s; ctx.stroke(); return;
      }
      ctx.fillStyle = step[1] === "groove" ? "#f7f3ea" : COL.cam; ctx.fill();
      ctx.strokeStyle = COL.camLine; ctx.lineWidth = 2; ctx.stroke();
    });
  }

  function drawCam(i) {
    var a = D.frames.angle[i], c = Math.cos(a), s = Math.sin(a), dx = D.frames.shift[i];
    if (D.groove) { drawGroove(c, s); }
    (D.groove ? [] : D.outline).forEach(function (pts, k) {
      var copies = D.closed ? [0] : [-D.period, 0, D.period];
      copies.forEach(function (off) {
        ctx.beginPath();
        var ymin = Infinity;
        for (var j = 0; j < pts.length; j += 2) {
          var x = pts[j], y = pts[j + 1];
          var u = x * c - y * s + dx + off, v = x * s + y * c;
          if (j === 0) { ctx.moveTo(X(u), Y(v)); } else { ctx.lineTo(X(u), Y(v)); }
          ymin = Math.min(ymin, y);
        }
        if (!D.closed) {
          var base = ymin - 0.15 * D.rmax;
          ctx.lineTo(X(pts[pts.length - 2] + dx + off), Y(base)); ctx.lineTo(X(pts[0] + dx + off), Y(base));
        }
        ctx.closePath();
        ctx.fillStyle = k === 0 ? COL.cam : COL.cam2; ctx.fill();
        ctx.strokeStyle = k === 0 ? COL.camLine : COL.cam2Line; ctx.lineWidth = 2;
        ctx.setLineDash(k === 0 ? [] : [6, 4]); ctx.stroke(); ctx.setLineDash([]);
      });
    });
    if (D.closed) {
      D.circles.forEach(function (ci) {
        if (ci.kind === "bore") { circle(0, 0, ci.r, "#fff", "#333", 1.2); }
        else { circle(0, 0, ci.r, null, "#888", 1, [4, 4]); }
      });
      // reference mark: the cam's 0° radius turns with the cam
      var r0 = 0.8 * (D.circles.length ? D.circles[0].r : D.rmax);
      line(0, 0, -s * r0, c * r0, COL.camLine, 2);
      circle(-s * r0, c * r0, 0.025 * D.rmax, COL.camLine);
      line(-0.06 * D.rmax, 0, 0.06 * D.rmax, 0, "#000", 1.2); line(0, -0.06 * D.rmax, 0, 0.06 * D.rmax, "#000", 1.2);
      drawArrow();
    }
  }

  function drawArrow() {
    var r = 1.1 * D.rmax, a0 = Math.PI * 1.12, a1 = Math.PI * 0.88, cw = D.sense > 0;
    var from = cw ? a0 : a1, to = cw ? a1 : a0;
    ctx.beginPath(); ctx.arc(X(0), Y(0), r * view.s, -from, -to, !cw ? true : false);
    ctx.strokeStyle = "#444"; ctx.lineWidth = 1.5; ctx.stroke();
    var tx = r * Math.cos(to), ty = r * Math.sin(to), d = cw ? -1 : 1;
    var hx = -Math.sin(to) * d, hy = Math.cos(to) * d, k = 0.07 * D.rmax;
    ctx.beginPath(); ctx.moveTo(X(tx + hx * k), Y(ty + hy * k));
    ctx.lineTo(X(tx - 0.5 * k * Math.cos(to)), Y(ty - 0.5 * k * Math.sin(to)));
    ctx.lineTo(X(tx + 0.5 * k * Math.cos(to)), Y(ty + 0.5 * k * Math.sin(to))); ctx.closePath();
    ctx.fillStyle = "#444"; ctx.fill();
    ctx.fillStyle = "#444"; ctx.font = "12px sans-serif";
    ctx.textAlign = "right"; ctx.textBaseline = "middle";
    ctx.fillText(cw ? "cw" : "ccw", X(-1.16 * D.rmax), Y(0));
    ctx.textAlign = "left"; ctx.textBaseline = "alphabetic";
  }

  function drawFollowers(i) {
    D.guides.forEach(function (g) { line(g[0], g[1], g[2], g[3], COL.guide, 4); });
    if (D.pivot) {
      var p = D.pivot, k = 0.05 * D.rmax;
      ctx.beginPath(); ctx.moveTo(X(p[0]), Y(p[1])); ctx.lineTo(X(p[0] - k), Y(p[1] - 1.6 * k));
      ctx.lineTo(X(p[0] + k), Y(p[1] - 1.6 * k)); ctx.closePath(); ctx.fillStyle = "#bbb"; ctx.fill();
    }
    D.followers.forEach(function (f) {
      var L = f.link, j = 4 * i;
      line(L[j], L[j + 1], L[j + 2], L[j + 3], COL.link, 5);
      if (f.face) {
        var F = f.face;
        line(F[j], F[j + 1], F[j + 2], F[j + 3], COL.face, 5);
      }
      if (f.arc) {  // a curved face: the arc of the face about its centre of curvature
        var A = f.arc, K = f.centre, h = 2 * i;
        ctx.beginPath(); ctx.arc(X(K[h]), Y(K[h + 1]), f.r * view.s, -A[h], -A[h + 1], true);
        ctx.strokeStyle = COL.face; ctx.lineWidth = 5; ctx.stroke();
      } else if (f.kind === "roller") {
        var C = f.centre, m = 2 * i;
        if (f.r > 0) { circle(C[m], C[m + 1], f.r, COL.roller, COL.rollerLine, 1.5); }
        circle(C[m], C[m + 1], 0.012 * D.rmax, "#333");
      }
      var P = f.contact, n = f.normal, q = 2 * i, a = 0.35 * D.rmax;
      line(P[q] - n[q] * a, P[q + 1] - n[q + 1] * a, P[q] + n[q] * a, P[q + 1] + n[q + 1] * a, COL.contact, 1.2, [5, 4]);
      circle(P[q], P[q + 1], 0.018 * D.rmax, COL.contact);
    });
    if (D.pivot) { circle(D.pivot[0], D.pivot[1], 0.03 * D.rmax, "#fff", "#333", 2); }
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
    ctx.beginPath(); ctx.moveTo(sx(i), top); ctx.lineTo(sx(i), top + h); ctx.strokeStyle = COL.contact; ctx.stroke();
    ctx.beginPath(); ctx.arc(sx(i), sy(S[i]), 3.5, 0, 2 * Math.PI); ctx.fillStyle = COL.contact; ctx.fill();
    ctx.fillStyle = COL.text; ctx.font = "11px sans-serif";
    ctx.fillText("S (" + D.lift_unit + ")", 4, top + 10);
    ctx.fillText(smax.toFixed(2), 4, top + 24); ctx.fillText(smin.toFixed(2), 4, top + h);
    ctx.fillText("0", left, top + h + 12);
    ctx.textAlign = "right";
    ctx.fillText(D.period.toFixed(0) + (D.unit === "°" ? "°" : " mm"), left + w, top + h + 12);
    ctx.textAlign = "left";
  }

  // a cylindrical cam draws its own scene (window.camfabCylinderScene); every other cam its profile and followers
  var scene = (D.cylinder && window.camfabCylinderScene)
    ? window.camfabCylinderScene({ ctx: ctx, D: D, X: X, Y: Y, line: line, view: view })
    : function (i) { drawCam(i); drawFollowers(i); };

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
    scene(i);
    ctx.restore();
    drawStrip(i);
    var unit = D.unit === "°" ? "°" : " mm";
    outAngle.textContent = D.frames.x[i].toFixed(1) + unit;
    outS.textContent = D.frames.S[i].toFixed(3) + " " + D.lift_unit;
    var txt = [], bad = false;
    D.frames.pa.forEach(function (pa, k) {
      if (!pa) { return; }
      txt.push((D.frames.pa.length > 1 ? "#" + (k + 1) + " " : "") + pa[i].toFixed(2) + "°");
      if (D.pa_limit !== null && Math.abs(pa[i]) > D.pa_limit) { bad = true; }
    });
    outPa.textContent = (txt.length ? txt.join(", ") : "n/a") + (D.pa_limit !== null ? " (limit ±" + D.pa_limit + "°)" : "");
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

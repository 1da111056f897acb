/* camfab report: a cylindrical cam's scene for the mechanism animation (vanilla JS, no network).
 * Inlined before the mechanism animation script, which runs the controls, the S strip and the readouts and calls this scene for the
 * view when its data (camfab.report.cylinder_animation) says "cylinder": the cylinder seen from the follower's
 * side (axis horizontal), turning — the groove's edges and generator lines turned by the frame's cam angle and
 * shown on the front half — and the roller at its exact position along the axis (the oscillating arm from its
 * pivot, or the translating follower's slide between its rails).
 */
window.camfabCylinderScene = function (api) {
  "use strict";
  var ctx = api.ctx, D = api.D, X = api.X, Y = api.Y, line = api.line, view = api.view;
  var COL = { body: "#cfe0f3", bodyLine: "#1f5fa8", groove: "#7d8fa6", mark: "rgba(31,95,168,0.35)",
              mark0: "#d46a00", link: "#555", roller: "#f2c14e", rollerLine: "#7a5a00", guide: "#999", text: "#333" };

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

  return function (i) { drawCylinder(i); drawFollower(i); };
};

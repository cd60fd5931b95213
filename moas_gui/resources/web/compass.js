/* The compass: drawing a rotator in SVG, and which heading a tap means.
   Headings are compass degrees, clockwise from north.  The compass shows the
   antenna's direction (the rotator's heading plus the antenna's offset); a tap
   asks for the rotator heading that points the antenna there. */
"use strict";

const MoasCompass = (() => {
  const NS = "http://www.w3.org/2000/svg";
  const R = 100;

  function norm(h) { h %= 360; if (h < 0) h += 360; return h >= 359.9999 ? 0 : h; }
  function point(radius, heading) {
    const a = heading * Math.PI / 180;
    return [radius * Math.sin(a), -radius * Math.cos(a)];
  }
  function el(name, attrs, parent) {
    const node = document.createElementNS(NS, name);
    for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, v);
    if (parent) parent.appendChild(node);
    return node;
  }
  function sector(start, span, cls, parent) {
    if (span >= 359.9) return el("circle", { cx: 0, cy: 0, r: R, class: cls }, parent);
    const [x1, y1] = point(R, start);
    const [x2, y2] = point(R, start + span);
    return el("path", { class: cls,
      d: `M0 0 L${x1.toFixed(2)} ${y1.toFixed(2)} A${R} ${R} 0 ${span > 180 ? 1 : 0} 1 ` +
         `${x2.toFixed(2)} ${y2.toFixed(2)} Z` }, parent);
  }
  function line(heading, cls, parent, inner = 0, outer = R) {
    const [x1, y1] = point(inner, heading);
    const [x2, y2] = point(outer, heading);
    return el("line", { x1, y1, x2, y2, class: cls }, parent);
  }

  /* The dead zone, overlap and stop of a rotator's travel, in antenna headings. */
  function travel(rot, offset) {
    if (rot.ccw_limit == null || rot.rotation == null || rot.rotation <= 0) return {};
    const start = norm(rot.ccw_limit + offset);
    if (rot.rotation < 360) return { dead: [norm(start + rot.rotation), 360 - rot.rotation], stop: start };
    const overlap = rot.rotation > 360 ? [start, Math.min(rot.rotation - 360, 360)] : null;
    const stop = rot.has_stop || rot.rotation > 360 ? start : null;
    return { overlap, stop };
  }

  /* Draws ``target`` ({rotator, offset, directions}) into ``svg``. */
  function draw(svg, target) {
    while (svg.firstChild) svg.removeChild(svg.firstChild);
    el("circle", { cx: 0, cy: 0, r: R, class: "face" }, svg);
    if (!target) return;
    const rot = target.rotator;
    const marks = travel(rot, target.offset);
    if (marks.overlap) sector(marks.overlap[0], marks.overlap[1], "overlap", svg);
    if (marks.dead) sector(marks.dead[0], marks.dead[1], "dead", svg);
    for (let h = 0; h < 360; h += 30) line(h, "tick", svg, h % 90 ? 90 : 84, R);
    for (const [h, name] of [[0, "N"], [90, "E"], [180, "S"], [270, "W"]]) {
      const [x, y] = point(R + 11, h);
      el("text", { x, y, class: "card" }, svg).textContent = name;
    }
    if (marks.stop != null) line(marks.stop, "stopline", svg, 60, R);
    for (const d of target.directions) {
      const [x, y] = point(78, d.heading);
      el("circle", { cx: x, cy: y, r: 9, class: d.active ? "dir active" : "dir" }, svg);
    }
    if (rot.moving && rot.target != null) line(norm(rot.target + target.offset), "target", svg, 0, R - 4);
    if (rot.heading != null && !rot.electrical) line(norm(rot.heading + target.offset), "needle", svg, 0, R - 14);
    el("circle", { cx: 0, cy: 0, r: 5, fill: "#ffb300" }, svg);
  }

  /* The rotator heading a tap at (clientX, clientY) asks for, or null at the centre. */
  function headingAt(svg, clientX, clientY, offset) {
    const box = svg.getBoundingClientRect();
    const scale = 240 / box.width;
    const x = (clientX - box.left) * scale - 120;
    const y = (clientY - box.top) * scale - 120;
    if (Math.hypot(x, y) < 8) return null;
    const antenna = norm(Math.atan2(x, -y) * 180 / Math.PI);
    return Math.round(norm(antenna - offset)) % 360;
  }

  return { draw, headingAt, norm };
})();

// The dashboard's plots, drawn with uPlot from the board the page carries (#board's data-board):
// one plot per metric, each night's value with its 95 % interval, the findings marked, E-divisive
// change points dashed; hover (or click, to hold) a night for its values and its commit's link;
// the filter box, the kind and the findings checkbox pick the plots shown. The address may name a
// filter and a night to show: index.html?q=grid+tetra&kind=counter&flagged=1&night=6.
(function () {
  "use strict";
  var board = JSON.parse(document.getElementById("board").dataset.board);
  var nights = {};
  board.nights.forEach(function (n) { nights[n.id] = n; });
  var COLORS = { regression: "#c62828", failed: "#c62828", improvement: "#2e7d32", change: "#ef6c00", suspect: "#ef6c00" };
  var LINE = { time_ratio: "#1565c0", instructions: "#6a1b9a", counter: "#00695c", criterion: "#4e342e" };

  function fmt(v) {
    if (v == null || !isFinite(v)) return "–";
    if (Number.isInteger(v)) return v.toLocaleString("en-US");
    if (Math.abs(v) >= 100) return v.toFixed(1);
    return v.toFixed(4);
  }

  function text(el, s) { el.appendChild(document.createTextNode(s)); }

  // The hover line: the night, its commit (a link when the page has a URL template), the value,
  // its interval and the findings of that night.
  function describe(el, p, i) {
    el.textContent = "";
    if (i == null) { text(el, "Hover a night for its values; click to hold it."); return; }
    var id = p.x[i], n = nights[id] || {};
    text(el, "night " + id + " (" + (n.started_at || "") + "), commit ");
    var short = (n.commit || "").slice(0, 10);
    if (n.url) {
      var a = document.createElement("a");
      a.href = n.url; a.className = "commit"; a.textContent = short; a.title = n.commit;
      el.appendChild(a);
    } else {
      var c = document.createElement("code"); c.textContent = short; el.appendChild(c);
    }
    text(el, ": " + fmt(p.y[i]) + (p.unit ? " " + p.unit : ""));
    if (p.lo[i] != null) text(el, ", 95 % interval [" + fmt(p.lo[i]) + ", " + fmt(p.hi[i]) + "] of " + p.n[i] + " samples");
    p.marks.forEach(function (m) {
      if (m.night !== id) return;
      var s = document.createElement("span");
      s.className = "mark " + m.verdict; s.textContent = m.verdict + ": " + m.message;
      text(el, " "); el.appendChild(s);
    });
  }

  // Error bars, change points and finding marks, over the series.
  function overlay(p) {
    return function (u) {
      var ctx = u.ctx, b = u.bbox, px = window.devicePixelRatio || 1;
      ctx.save();
      ctx.lineWidth = px;
      ctx.strokeStyle = LINE[p.kind] || "#333";
      for (var i = 0; i < p.x.length; i++) {
        if (p.lo[i] == null) continue;
        var x = u.valToPos(p.x[i], "x", true), y0 = u.valToPos(p.lo[i], "y", true), y1 = u.valToPos(p.hi[i], "y", true);
        ctx.beginPath();
        ctx.moveTo(x, y0); ctx.lineTo(x, y1);
        ctx.moveTo(x - 3 * px, y0); ctx.lineTo(x + 3 * px, y0);
        ctx.moveTo(x - 3 * px, y1); ctx.lineTo(x + 3 * px, y1);
        ctx.stroke();
      }
      ctx.setLineDash([4 * px, 3 * px]);
      ctx.strokeStyle = "#555";
      p.change_points.forEach(function (cx) {
        var x = u.valToPos(cx, "x", true);
        ctx.beginPath(); ctx.moveTo(x, b.top); ctx.lineTo(x, b.top + b.height); ctx.stroke();
      });
      ctx.setLineDash([]);
      p.marks.forEach(function (m) {
        var i = p.x.indexOf(m.night);
        if (i < 0) return;
        var x = u.valToPos(m.night, "x", true), y = u.valToPos(p.y[i], "y", true), r = 6 * px;
        ctx.fillStyle = ctx.strokeStyle = COLORS[m.verdict] || "#333";
        ctx.lineWidth = 2 * px;
        ctx.beginPath(); ctx.arc(x, y, r, 0, 2 * Math.PI); ctx.stroke();
        ctx.beginPath();
        ctx.moveTo(x - r, b.top); ctx.lineTo(x + r, b.top); ctx.lineTo(x, b.top + 1.6 * r);
        ctx.closePath(); ctx.fill();
      });
      ctx.restore();
    };
  }

  function draw(section) {
    var p = board.plots[+section.dataset.i];
    var chart = section.querySelector(".chart"), hover = section.querySelector(".hover");
    var lo = Math.min.apply(null, p.y.concat(p.lo.filter(function (v) { return v != null; })));
    var hi = Math.max.apply(null, p.y.concat(p.hi.filter(function (v) { return v != null; })));
    var width = Math.max(320, (section.clientWidth || 460) - 20);
    var opts = {
      width: width,
      height: 190,
      scales: {
        x: { time: false, range: function (u, a, b) { return [a - 0.5, b + 0.5]; } },
        y: { range: function () { return uPlot.rangeNum(lo, hi, 0.1, true); } }
      },
      axes: [
        {
          label: "night",
          size: 30,
          labelSize: 18,
          // Nights are whole: ticks only at integers.
          incrs: [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000],
          values: function (u, splits) { return splits.map(function (v) { return Number.isInteger(v) ? String(v) : ""; }); }
        },
        {
          size: function (u, values) {
            var w = (values || []).reduce(function (m, s) { return Math.max(m, String(s).length); }, 4);
            return 14 + 7 * w;
          }
        }
      ],
      series: [
        { label: "night", value: function (u, v) { return v == null ? "–" : String(v); } },
        {
          label: p.unit || p.kind,
          stroke: LINE[p.kind] || "#333",
          width: 1.5,
          points: { show: true, size: 6 },
          value: function (u, v) { return fmt(v); }
        }
      ],
      cursor: { lock: true, drag: { x: false, y: false } },
      legend: { live: true },
      hooks: {
        draw: [overlay(p)],
        setCursor: [function (u) { describe(hover, p, u.cursor.idx); }],
        // A night named in the address (index.html?night=ID) is shown in every plot that holds
        // it, once the plot is laid out.
        ready: [function (u) {
          var i = p.x.indexOf(held);
          if (i >= 0) u.setCursor({ left: u.valToPos(p.x[i], "x"), top: u.valToPos(p.y[i], "y") });
        }]
      }
    };
    new uPlot(opts, [p.x, p.y], chart);
  }

  var q = new URLSearchParams(window.location.search);
  var held = q.get("night") ? +q.get("night") : null;
  var sections = Array.prototype.slice.call(document.querySelectorAll("section.plot"));
  sections.forEach(draw);

  var filter = document.getElementById("filter"), kind = document.getElementById("kind");
  var flagged = document.getElementById("flagged"), shown = document.getElementById("shown");
  function apply() {
    var terms = filter.value.toLowerCase().split(/\s+/).filter(Boolean);
    var n = 0;
    sections.forEach(function (s) {
      var name = s.dataset.name.toLowerCase();
      var ok = terms.every(function (t) { return name.indexOf(t) >= 0; }) &&
        (!kind.value || s.dataset.kind === kind.value) && (!flagged.checked || s.dataset.flag !== "");
      s.hidden = !ok;
      if (ok) n++;
    });
    shown.textContent = n + " of " + sections.length + " plots";
  }
  // The filter can come with the address: index.html?q=grid+tetra&kind=counter&flagged=1.
  if (q.get("q")) filter.value = q.get("q");
  if (q.get("kind")) kind.value = q.get("kind");
  if (q.get("flagged")) flagged.checked = true;
  filter.addEventListener("input", apply);
  kind.addEventListener("change", apply);
  flagged.addEventListener("change", apply);
  apply();
  // The plots changed the page's height: go again to the part the address names.
  var target = window.location.hash && document.getElementById(window.location.hash.slice(1));
  if (target) target.scrollIntoView();
})();

/* fuzzoff HTML report: zoomable timelines (uPlot) and the sortable, filterable index.
 *
 * Each figure.timeline names a JSON block with its data (html_plot.py). Its plots are
 * built when the figure comes near the screen. Every text from a recording reaches the page
 * through textContent or a title attribute, never as markup.
 */
(() => {
  "use strict";
  document.documentElement.classList.add("js"); // the timelines will be drawn: no "needs JS" note

  const AXIS = 118; // width of every plot's left axis, so their plotting areas line up
  const MARK_GAP = 14; // markers closer than this (px) are drawn as one group
  const LABEL_GAP = 8; // room kept between two note labels (px)
  const MIN_LABEL = 48; // a note label shorter than this (px) is left out, not cut
  const SEV_RANK = { info: 0, warning: 1, error: 2 };
  const COLORS = {
    error: "#c62828", warning: "#b26a00", info: "#1565c0", ok: "#2e7d32",
    keepalive: "#1565c0", rate: "#b26a00", loss: "#c62828",
    alt: "#1565c0", x: "#c2185b", y: "#2e7d32",
    "m-offboard": "#2e7d32", "m-unknown": "#9e9e9e", "m-0": "#5c6bc0", "m-1": "#8d6e63",
    "m-2": "#00838f", "m-3": "#6a1b9a", "m-4": "#ef6c00", "m-5": "#455a64",
    "s-ok": "#66bb6a", "s-lost": "#e57373", sp: "#42a5f5",
  };
  const FONT = "11px system-ui, sans-serif";

  const el = (tag, cls, text) => {
    const e = document.createElement(tag);
    if (cls) e.className = cls;
    if (text != null) e.textContent = text;
    return e;
  };

  const seconds = (t, span) => {
    if (span > 600) {
      const m = Math.floor(t / 60);
      const s = t - m * 60;
      return `${m}:${s < 10 ? "0" : ""}${s.toFixed(span > 3600 ? 0 : 1)}`;
    }
    return span < 2 ? t.toFixed(3) : span < 20 ? t.toFixed(2) : t.toFixed(1);
  };

  const clock = (start, t) => {
    if (start == null) return "";
    const d = new Date((start + t) * 1000);
    return `${d.toISOString().slice(11, 23)} UTC`;
  };

  const ROWS = ["failsafes, errors", "PX4 messages", "commands"];
  const noteRow = (n) => (n[1] === "cmd" || n[1] === "ack" ? 2 : n[1] === "failsafe" || n[2] === "error" ? 0 : 1);

  class Timeline {
    constructor(fig) {
      this.fig = fig;
      this.data = JSON.parse(document.getElementById(fig.dataset.plot).textContent);
      this.start = fig.dataset.start ? Number(fig.dataset.start) : null;
      this.full = [0, Math.max(this.data.end, 1e-3)];
      this.view = this.full.slice();
      this.plots = [];
      this.syncing = false;
      this.key = `tl-${fig.dataset.plot}`;
      this.build();
    }

    width() {
      return Math.max(320, Math.floor(this.body.clientWidth));
    }

    build() {
      const fig = this.fig;
      fig.querySelector(".needs-js")?.remove();
      const bar = el("div", "toolbar");
      const button = (text, title, action) => {
        const b = el("button", null, text);
        b.type = "button";
        b.title = title;
        b.addEventListener("click", action);
        bar.append(b);
        return b;
      };
      button("−", "zoom out (Ctrl + wheel)", () => this.zoom(2));
      button("+", "zoom in (Ctrl + wheel, or drag across a plot)", () => this.zoom(0.5));
      button("◀", "move left (Shift + wheel)", () => this.pan(-0.5));
      button("▶", "move right (Shift + wheel)", () => this.pan(0.5));
      button("whole recording", "show the whole recording (double-click a plot)", () =>
        this.show(this.full[0], this.full[1]));
      this.rangeText = el("span", "range");
      bar.append(this.rangeText);
      this.body = el("div", "plots");
      fig.append(bar, this.body);
      this.marks = el("div", "lane marks");
      this.marks.setAttribute("aria-label", "findings");
      this.body.append(this.marks);
      const d = this.data;
      if (d.keepalive) this.plots.push(this.keepalivePlot(d.keepalive));
      else this.body.append(el("p", "none", "No keep-alive messages from this vehicle."));
      if (d.position || d.setpoint) this.plots.push(this.positionPlot(d.position, d.setpoint));
      this.plots.push(this.bandsPlot(d.bands));
      this.notes = el("div", "lane notes");
      this.notes.setAttribute("aria-label", "PX4 messages, commands and acks");
      this.body.append(this.notes);
      if (!d.notes.length) this.notes.append(el("span", "none", "no text messages or commands recorded"));
      // only the rows that have something, one under the other
      this.rowTop = {};
      ROWS.forEach((name, row) => {
        if (!d.notes.some((n) => noteRow(n) === row)) return;
        this.rowTop[row] = 18 * Object.keys(this.rowTop).length;
        const caption = el("span", "row-name", name);
        caption.style.top = `${this.rowTop[row]}px`;
        caption.style.width = `${AXIS - 6}px`;
        this.notes.append(caption);
      });
      this.notes.style.height = `${Math.max(18, 18 * Object.keys(this.rowTop).length)}px`;
      if (d.more_notes) fig.append(el("p", "none", `${d.more_notes} more messages not drawn`));
      this.readout = el("div", "readout", "\u00a0");
      this.body.append(this.readout);
      this.markEls = d.marks.map((m) => {
        const a = el("a", `mark ${m[2]}`);
        a.id = `mark-${m[4]}`;
        a.href = `#finding-${m[4]}`;
        a.title = m[5];
        a.setAttribute("aria-label", m[5]);
        a.dataset.t = m[0];
        this.marks.append(a);
        return a;
      });
      this.noteEls = d.notes.map((n) => {
        const item = el("span", `note ${n[1]} ${n[2]}`);
        item.title = `${seconds(n[0], 1)} s: ${n[4]}`;
        item.append(el("span", "tick"), el("span", "label", n[3]));
        this.notes.append(item);
        return item;
      });
      const measure = document.createElement("canvas").getContext("2d");
      measure.font = FONT;
      this.noteWidths = d.notes.map((n) => {
        measure.font = n[1] === "failsafe" ? `600 ${FONT}` : FONT; // failsafe labels are bold
        return measure.measureText(n[3]).width + 8;
      });
      this.groupEls = [];
      fig.addEventListener("wheel", (e) => this.wheel(e), { passive: false });
      fig.addEventListener("keydown", (e) => this.key_(e));
      new ResizeObserver(() => this.resize()).observe(this.body);
      this.show(this.full[0], this.full[1]);
    }

    common(height, extra) {
      const self = this;
      return Object.assign({
        width: this.width(),
        height,
        padding: [10, 18, 0, 0],
        scales: { x: { time: false, auto: false, range: (u, min, max) => [min, max] } },
        cursor: {
          drag: { x: true, y: false, setScale: true },
          sync: { key: this.key, setSeries: false },
          points: { show: false },
          bind: {
            dblclick: () => () => {
              self.show(self.full[0], self.full[1]);
              return null;
            },
          },
        },
        legend: { show: false },
        hooks: {
          setScale: [(u, key) => {
            if (key === "x" && !self.syncing) self.show(u.scales.x.min, u.scales.x.max, u);
          }],
          setCursor: [(u) => self.cursor(u)],
        },
      }, extra);
    }

    xAxis(last) {
      return {
        size: last ? 34 : 26,
        font: FONT,
        values: (u, splits) => {
          const span = u.scales.x.max - u.scales.x.min;
          return splits.map((t) => seconds(t, span));
        },
        label: last ? "time (s) from the recording's start" : undefined,
        labelSize: last ? 14 : 0,
        labelFont: FONT,
      };
    }

    keepalivePlot(k) {
      const rows = [[k.t, k.v]];
      if (k.tail) rows.push([k.tail[0], k.tail[1]]);
      const data = uPlot.join(rows);
      // no dots: the rise through a gap is drawn from computed points, not from messages
      const series = [{}, {
        label: "keep-alive interval", stroke: COLORS.keepalive, width: 1.2, points: { show: false },
      }];
      if (k.tail) {
        series.push({
          label: "no keep-alive until the end", stroke: COLORS.keepalive, dash: [4, 3],
          points: { show: false },
        });
      }
      const [lo, hi] = k.y;
      const opts = this.common(190, {
        class: "keepalive",
        series,
        scales: Object.assign(this.common(0).scales, { y: { distr: 3, log: 10, range: [lo, hi] } }),
        axes: [this.xAxis(), {
          size: AXIS,
          font: FONT,
          label: "keep-alive interval",
          labelSize: 14,
          labelFont: FONT,
          splits: () => {
            const out = [];
            for (let v = lo; v <= hi * 1.0001; v *= 10) out.push(v);
            return out;
          },
          values: (u, splits) => splits.map((v) => (v < 1 ? `${+(v * 1000).toPrecision(3)} ms` : `${v} s`)),
        }],
      });
      opts.hooks.draw = [(u) => {
        this.drawSpans(u);
        const ctx = u.ctx;
        const { left, width } = u.bbox;
        ctx.save();
        ctx.font = `bold ${Math.round(11 * devicePixelRatio)}px system-ui, sans-serif`;
        k.lines.forEach(([v, label, cls], i) => {
          const y = Math.round(u.valToPos(v, "y", true)) + 0.5;
          ctx.strokeStyle = ctx.fillStyle = COLORS[cls];
          ctx.setLineDash(cls === "rate" ? [6, 3] : [2, 2]);
          ctx.lineWidth = devicePixelRatio;
          ctx.beginPath();
          ctx.moveTo(left, y);
          ctx.lineTo(left + width, y);
          ctx.stroke();
          // the rate line is labelled at the right below it, the loss line at the left above
          const below = i === 0;
          ctx.textAlign = below ? "right" : "left";
          ctx.textBaseline = below ? "top" : "bottom";
          const x = below ? left + width - 4 * devicePixelRatio : left + 4 * devicePixelRatio;
          ctx.fillText(label, x, y + (below ? 3 : -3) * devicePixelRatio);
        });
        ctx.restore();
      }];
      return new uPlot(opts, data, this.body);
    }

    positionPlot(pos, sp) {
      const rows = [];
      const series = [{ label: "time (s)", value: (u, v) => (v == null ? "--" : seconds(v, 1)) }];
      const add = (cols, what, dash) => {
        if (!cols) return;
        rows.push([cols[0], cols[1], cols[2], cols[3]]);
        [["alt", "altitude"], ["x", "x (north)"], ["y", "y (east)"]].forEach(([k, name]) =>
          series.push({
            label: `${name} ${what}`, stroke: COLORS[k], width: 1.2, dash, spanGaps: true,
            points: { show: false },
          }));
      };
      add(pos, "of the vehicle", undefined);
      add(sp, "setpoint", [5, 4]);
      const data = uPlot.join(rows);
      const opts = this.common(170, {
        class: "position",
        series,
        legend: { show: true, live: true },
        axes: [this.xAxis(), {
          size: AXIS, font: FONT, label: "position (m)",
          labelSize: 14, labelFont: FONT,
        }],
      });
      return new uPlot(opts, data, this.body);
    }

    bandsPlot(bands) {
      const n = bands.length;
      const H = 18;
      const self = this;
      const opts = this.common(n * H + 34 + 8, {
        class: "bands",
        series: [{}, { show: false }],
        scales: Object.assign(this.common(0).scales, { y: { auto: false, range: [0, n] } }),
        axes: [this.xAxis(true), {
          size: AXIS,
          font: FONT,
          grid: { show: false },
          ticks: { show: false },
          label: "",
          labelSize: 14,
          splits: () => bands.map((_, i) => n - i - 0.5),
          values: (u) => bands.map((b) => (b.name.length > 19 ? `${b.name.slice(0, 18)}…` : b.name)),
        }],
      });
      opts.hooks.draw = [(u) => {
        const ctx = u.ctx;
        const { left, top, width, height } = u.bbox;
        const h = height / n;
        const px = devicePixelRatio;
        ctx.save();
        ctx.beginPath();
        ctx.rect(left, top, width, height);
        ctx.clip();
        ctx.font = `${Math.round(10 * px)}px system-ui, sans-serif`;
        ctx.textBaseline = "middle";
        ctx.textAlign = "left";
        bands.forEach((b, i) => {
          const y = top + i * h + px;
          ctx.fillStyle = "#f1f1f1";
          ctx.fillRect(left, y, width, h - 2 * px);
          if (!b.segs.length) {
            ctx.fillStyle = "#777";
            ctx.fillText(b.empty, left + 4 * px, y + h / 2);
          }
          for (const [s, e, label, css] of b.segs) {
            const x0 = Math.max(u.valToPos(s, "x", true), left - 2);
            const x1 = Math.min(u.valToPos(e, "x", true), left + width + 2);
            if (x1 < left || x0 > left + width) continue;
            const w = Math.max(x1 - x0, px);
            const classes = css.split(" ");
            ctx.globalAlpha = classes.includes("disarmed") ? 0.45 : 1;
            ctx.fillStyle = COLORS[classes[0]] || "#888";
            ctx.fillRect(x0, y, w, h - 2 * px);
            ctx.globalAlpha = 1;
            if (label && ctx.measureText(label).width + 6 * px < w) {
              ctx.fillStyle = "#fff";
              ctx.fillText(label, Math.max(x0, left) + 3 * px, y + h / 2);
            }
          }
        });
        ctx.restore();
      }];
      this.bandList = bands;
      return new uPlot(opts, [[this.full[0], this.full[1]], [null, null]], this.body);
    }

    drawSpans(u) {
      const ctx = u.ctx;
      const { top, height } = u.bbox;
      ctx.save();
      for (const m of this.data.marks) {
        if (m[1] == null) continue;
        const x0 = u.valToPos(m[0], "x", true);
        const x1 = u.valToPos(m[1], "x", true);
        ctx.fillStyle = COLORS[m[2]];
        ctx.globalAlpha = 0.1;
        ctx.fillRect(x0, top, Math.max(x1 - x0, 1), height);
      }
      ctx.restore();
    }

    /* -- the visible range -------------------------------------------------------------- */

    show(min, max, from) {
      const [f0, f1] = this.full;
      let span = Math.min(Math.max(max - min, (f1 - f0) * 1e-5, 1e-3), f1 - f0);
      min = Math.min(Math.max(min, f0), f1 - span);
      this.view = [min, min + span];
      this.syncing = true;
      try {
        for (const u of this.plots) {
          if (u !== from || u.scales.x.min !== min || u.scales.x.max !== min + span)
            u.setScale("x", { min, max: min + span });
        }
      } finally {
        this.syncing = false;
      }
      this.layout();
      const whole = `${seconds(f1 - f0, f1 - f0)} s`;
      const start = this.start == null ? "" : `; ${clock(this.start, this.view[0])}`;
      this.rangeText.textContent =
        `showing ${seconds(this.view[0], span)}–${seconds(this.view[1], span)} s of ${whole}${start}`;
      this.fig.dataset.view = `${this.view[0]} ${this.view[1]}`;
    }

    zoom(factor, at) {
      const [a, b] = this.view;
      const c = at ?? (a + b) / 2;
      this.show(c - (c - a) * factor, c + (b - c) * factor);
    }

    pan(fraction) {
      const [a, b] = this.view;
      const d = (b - a) * fraction;
      this.show(a + d, b + d);
    }

    wheel(e) {
      const u = this.plots[0];
      if (!u) return;
      if (e.ctrlKey || e.metaKey) {
        e.preventDefault();
        const rect = u.over.getBoundingClientRect();
        const at = u.posToVal(e.clientX - rect.left, "x");
        this.zoom(e.deltaY > 0 ? 1.25 : 0.8, Math.min(Math.max(at, this.view[0]), this.view[1]));
      } else if (e.shiftKey || Math.abs(e.deltaX) > Math.abs(e.deltaY)) {
        e.preventDefault();
        this.pan(((e.shiftKey ? e.deltaY : e.deltaX) > 0 ? 1 : -1) * 0.1);
      }
    }

    key_(e) {
      const keys = { "+": () => this.zoom(0.5), "=": () => this.zoom(0.5), "-": () => this.zoom(2),
        ArrowLeft: () => this.pan(-0.2), ArrowRight: () => this.pan(0.2),
        "0": () => this.show(this.full[0], this.full[1]) };
      if (keys[e.key] && e.target === this.fig) {
        e.preventDefault();
        keys[e.key]();
      }
    }

    resize() {
      const w = this.width();
      for (const u of this.plots) if (u.width !== w) u.setSize({ width: w, height: u.height });
      this.layout();
    }

    focus(ident) {
      const m = this.data.marks.find((x) => x[4] === ident);
      if (!m) return;
      const [f0, f1] = this.full;
      const end = m[1] ?? m[0];
      const pad = Math.max((end - m[0]) * 0.5, (f1 - f0) * 0.01, 0.05);
      this.show(m[0] - pad, end + pad);
    }

    /* -- lanes laid out over the plots --------------------------------------------------- */

    x(t) {
      const u = this.plots[0];
      return u.over.offsetLeft + u.valToPos(t, "x");
    }

    inView(t) {
      return t >= this.view[0] && t <= this.view[1];
    }

    layout() {
      if (!this.plots.length) return;
      const plotWidth = this.plots[0].bbox.width / devicePixelRatio;
      this.layoutMarks(plotWidth);
      this.layoutNotes(plotWidth);
    }

    layoutMarks(plotWidth) {
      for (const g of this.groupEls) g.remove();
      this.groupEls = [];
      const shown = [];
      this.data.marks.forEach((m, i) => {
        const a = this.markEls[i];
        if (!this.inView(m[0])) {
          a.hidden = true;
          return;
        }
        shown.push([this.x(m[0]), m, a]);
      });
      shown.sort((p, q) => p[0] - q[0]);
      const groups = [];
      for (const item of shown) {
        const g = groups[groups.length - 1];
        if (g && item[0] - g.last < MARK_GAP) {
          g.items.push(item);
          g.last = item[0];
        } else {
          groups.push({ items: [item], last: item[0] });
        }
      }
      for (const g of groups) {
        const x = g.items[0][0];
        if (g.items.length === 1) {
          const a = g.items[0][2];
          a.hidden = false;
          a.style.left = `${x}px`;
          continue;
        }
        for (const [, , a] of g.items) a.hidden = true;
        const worst = g.items.reduce((w, [, m]) => (SEV_RANK[m[2]] > SEV_RANK[w] ? m[2] : w), "info");
        const codes = {};
        for (const [, m] of g.items) codes[m[3]] = (codes[m[3]] || 0) + 1;
        const summary = Object.entries(codes).map(([c, k]) => `${c} ×${k}`).join(", ");
        const t0 = g.items[0][1][0];
        const t1 = g.items[g.items.length - 1][1][0];
        const group = el("a", `mark group ${worst}`, String(g.items.length));
        group.href = `#finding-${g.items[0][1][4]}`;
        group.title = `${g.items.length} findings from ${seconds(t0, 1)} s to ${seconds(t1, 1)} s: ${summary}` +
          (t1 - t0 > 1e-3 ? " (click to zoom in)" : "");
        group.style.left = `${(x + g.last) / 2}px`;
        if (t1 - t0 > 1e-3) {
          group.addEventListener("click", (e) => {
            e.preventDefault();
            const pad = Math.max((t1 - t0) * 0.25, 1e-3);
            this.show(t0 - pad, t1 + pad);
          });
        }
        this.marks.append(group);
        this.groupEls.push(group);
      }
      this.marks.dataset.groups = String(groups.length);
    }

    layoutNotes(plotWidth) {
      // three rows: PX4's failsafe and error messages, its other messages, the commands with
      // their acks; a label runs at most up to the next item of its row (zoom in for the rest)
      const right = this.plots[0].over.offsetLeft + plotWidth;
      const rows = { 0: [], 1: [], 2: [] };
      this.data.notes.forEach((n, i) => {
        const item = this.noteEls[i];
        item.hidden = !this.inView(n[0]);
        if (item.hidden) return;
        const row = noteRow(n);
        const x = this.x(n[0]);
        item.style.left = `${x}px`;
        item.style.top = `${this.rowTop[row]}px`;
        rows[row].push([x, i]);
      });
      for (const items of Object.values(rows)) {
        items.sort((p, q) => p[0] - q[0]);
        let end = -Infinity;
        items.forEach(([x, i], k) => {
          // a label may run up to the next item of its row, cut short with an ellipsis
          const next = k + 1 < items.length ? items[k + 1][0] : right;
          const room = Math.min(next, right) - x - LABEL_GAP;
          const w = Math.min(this.noteWidths[i], room);
          const label = this.noteEls[i].lastChild;
          const fits = x >= end + LABEL_GAP && w >= Math.min(MIN_LABEL, this.noteWidths[i]);
          label.hidden = !fits;
          label.style.maxWidth = fits ? `${Math.floor(w - 5)}px` : "";
          if (fits) end = x + w;
        });
      }
    }

    cursor(u) {
      const idx = u.cursor.left;
      if (idx == null || idx < 0) return;
      const t = u.posToVal(u.cursor.left, "x");
      if (!Number.isFinite(t)) return;
      const parts = [`${seconds(t, this.view[1] - this.view[0])} s`];
      if (this.start != null) parts.push(clock(this.start, t));
      for (const b of this.bandList || []) {
        const seg = b.segs.find(([s, e]) => s <= t && t <= e);
        if (seg && seg[2]) parts.push(`${b.name}: ${seg[2]}`);
      }
      this.readout.textContent = parts.join(" · ");
    }
  }

  /* -- figures are built when they come near the screen, or when a link points into them -- */

  const built = new Map();
  const build = (fig) => {
    if (!built.has(fig)) built.set(fig, new Timeline(fig));
    return built.get(fig);
  };
  const figures = [...document.querySelectorAll("figure.timeline[data-plot]")];
  const seen = new IntersectionObserver((entries) => {
    for (const e of entries) {
      if (e.isIntersecting) {
        seen.unobserve(e.target);
        build(e.target);
      }
    }
  }, { rootMargin: "600px 0px" });
  figures.forEach((f) => seen.observe(f));

  const follow = () => {
    const id = decodeURIComponent(location.hash.slice(1));
    if (!id.startsWith("mark-")) return;
    const ident = id.slice(5);
    const fig = figures.find((f) => f.dataset.marks && f.dataset.marks.split(" ").includes(ident));
    if (!fig) return;
    const tl = build(fig);
    tl.focus(ident);
    document.getElementById(id)?.scrollIntoView({ block: "center" });
  };
  window.addEventListener("hashchange", follow);
  follow();

  /* -- the index of recordings: sort by a column, filter by severity, rule or name -------- */

  const index = document.querySelector("table.index");
  if (index) {
    const body = index.tBodies[0];
    const rows = [...body.rows];
    const controls = document.querySelector(".index-controls");
    controls.hidden = false;
    const [severity, rule, text] = ["severity", "rule", "text"].map((n) => controls.querySelector(`[name=${n}]`));
    const count = controls.querySelector(".count");
    const apply = () => {
      const level = severity.value;
      const code = rule.value;
      const words = text.value.trim().toLowerCase();
      let shown = 0;
      for (const row of rows) {
        const worst = row.dataset.worst;
        const ok = (!level || (level === "none" ? worst === "none" : SEV_RANK[worst] >= SEV_RANK[level])) &&
          (!code || row.dataset.rules.split(" ").includes(code)) &&
          (!words || row.dataset.path.toLowerCase().includes(words));
        row.hidden = !ok;
        const section = document.getElementById(row.dataset.file);
        if (section) section.hidden = !ok;
        if (ok) shown++;
      }
      count.textContent = `${shown} of ${rows.length} recordings`;
    };
    [severity, rule, text].forEach((c) => c.addEventListener("input", apply));
    for (const th of index.tHead.rows[0].cells) {
      const b = th.querySelector("button");
      if (!b) continue;
      b.addEventListener("click", () => {
        const col = th.cellIndex;
        const numeric = th.dataset.type === "number";
        const up = th.getAttribute("aria-sort") !== "ascending";
        for (const other of index.tHead.rows[0].cells) other.removeAttribute("aria-sort");
        th.setAttribute("aria-sort", up ? "ascending" : "descending");
        const key = (r) => r.cells[col].dataset.sort ?? r.cells[col].textContent;
        rows.sort((p, q) => {
          const a = key(p);
          const b2 = key(q);
          const c = numeric ? Number(a) - Number(b2) : a.localeCompare(b2);
          return up ? c : -c;
        });
        body.append(...rows);
      });
    }
    apply();
  }
})();

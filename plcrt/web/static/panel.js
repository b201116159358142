// plcrt panel: the page's side of the websocket protocol (docs/panel.md).
// Program text (titles, comments, symbols, STL) is only ever written with
// textContent or inside SVG that the server built with XML escaping and
// that is parsed as XML (DOMParser), never as HTML.
"use strict";

const $ = (id) => document.getElementById(id);
const SVGNS = "http://www.w3.org/2000/svg";
const P = {
  ws: null, hello: null, block: "OB1", frame: null, nets: {}, io: {},
  kinds: {}, pressed: {}, trend: { signals: [], t: [], v: [], end: 0 },
  axisHist: [], lastSeq: 0,
};
window.plcrtPanel = P;   // for the tests and the curious

function el(tag, attrs, text) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (k === "class") e.className = v; else e.setAttribute(k, v);
  }
  if (text !== undefined && text !== null) e.textContent = String(text);
  return e;
}

function send(msg) {
  if (P.ws && P.ws.readyState === WebSocket.OPEN) P.ws.send(JSON.stringify(msg));
}

function log(message, level) {
  const li = el("li", { class: level || "info" }, message);
  $("log").prepend(li);
  while ($("log").children.length > 50) $("log").lastChild.remove();
}

// ---------------------------------------------------------------- connection
function connect() {
  const proto = location.protocol === "https:" ? "wss:" : "ws:";
  const ws = new WebSocket(proto + "//" + location.host + "/ws");
  P.ws = ws;
  ws.onopen = () => { $("conn").textContent = "connected"; };
  ws.onclose = () => {
    offline();
    setTimeout(connect, 1000);
  };
  ws.onmessage = (ev) => {
    let msg;
    try { msg = JSON.parse(ev.data); } catch (e) { return; }
    const h = HANDLERS[msg.type];
    if (h) h(msg);
  };
}

const HANDLERS = {
  hello: onHello,
  frame: onFrame,
  trend: onTrend,
  error: (m) => log((m.request ? m.request + ": " : "") + m.message, "error"),
  notice: (m) => log(m.message, m.level),
  check: onCheck,
  diagnostics: onDiagnostics,
};

// The server stopped or the connection dropped: say so (the last frame's
// "running" is no longer true) until a new hello arrives.
function offline() {
  const was = !document.body.classList.contains("offline");
  document.body.classList.add("offline");
  $("conn").textContent = "disconnected";
  $("conn").classList.add("offline");
  $("runstate").textContent = "disconnected";
  $("runstate").className = "offline";
  $("rate").textContent = "";
  if (was) log("disconnected from the panel server: reconnecting ...", "error");
}

function online() {
  document.body.classList.remove("offline");
  $("conn").classList.remove("offline");
  $("runstate").classList.remove("offline");
}

// ---------------------------------------------------------------- hello
function onHello(h) {
  online();
  P.hello = h;
  P.nets = {};
  P.axisHist = [];
  P.trend = { signals: [], t: [], v: [], end: 0 };
  $("files").textContent = h.files.join(", ");
  buildTabs(h);
  const ids = h.blocks.map((b) => b.id);
  showBlock(ids.includes(P.block) ? P.block : ids[0]);
  buildIO(h);
  buildLesson(h);
  $("axes").hidden = !(h.axes.length || h.drives.length);
  $("axis-list").replaceChildren();
  P.axisEls = [];
  for (const a of h.axes) P.axisEls.push(buildAxis("EM253 slot " + a.slot + " axis " + a.axis, a));
  for (const d of h.drives) P.axisEls.push(buildAxis("drive " + d.node + " (" + d.model + ")", d));
  onDiagnostics(h.diagnostics || { items: [], more: null });
  ariaIO(P.frame);
  if (window.plcrtEditor) window.plcrtEditor.onHello(h);   // editor.js
  if (window.plcrtMachines) window.plcrtMachines.onHello(h);   // machines.js
}

function buildTabs(h) {
  const tabs = $("tabs");
  tabs.replaceChildren();
  for (const b of h.blocks) {
    const label = b.id + (b.name && b.name !== b.id ? " " + b.name : "");
    const btn = el("button", { "data-block": b.id, title: b.title || "" }, label);
    btn.addEventListener("click", () => showBlock(b.id));
    tabs.append(btn);
  }
}

// Frames carry the status of the networks on screen only (a long block
// would cost the scan its time otherwise).
P.visible = new Set();
const seen = new IntersectionObserver((entries) => {
  for (const e of entries) {
    const id = e.target.dataset.net;
    if (e.isIntersecting) P.visible.add(id); else P.visible.delete(id);
  }
  clearTimeout(P.viewTimer);
  P.viewTimer = setTimeout(sendView, 50);
});

function sendView() {
  send({ type: "view", block: P.block, networks: [...P.visible].slice(0, 1000) });
}

function showBlock(id) {
  P.block = id;
  P.visible = new Set();
  seen.disconnect();
  send({ type: "view", block: id });
  for (const b of $("tabs").children) b.classList.toggle("active", b.dataset.block === id);
  const box = $("networks");
  box.replaceChildren();
  P.nets = {};
  const block = P.hello.blocks.find((b) => b.id === id);
  if (!block) return;
  if (block.title) box.append(el("h2", {}, block.title));
  if (block.comment) box.append(el("div", { class: "comment" }, block.comment));
  for (const n of block.networks) box.append(buildNetwork(n));
  if (P.frame) onFrame(P.frame);
}

function buildNetwork(n) {
  const div = el("div", { class: "net", "data-net": n.id });
  const head = el("div", { class: "net-head" });
  const bp = el("button", { class: "bp", title: "breakpoint", "aria-label": "breakpoint " + n.id });
  bp.hidden = !P.hello.breakable;
  bp.addEventListener("click", () => {
    send({ type: bp.classList.contains("set") ? "unbreak" : "break", network: n.id });
  });
  head.append(bp, el("span", { class: "num" }, "Network " + n.number), el("span", {}, n.title));
  div.append(head);
  if (n.comment) div.append(el("div", { class: "comment" }, n.comment));
  const entry = { div, bp, k: [], v: [] };
  if (n.svg) {
    const doc = new DOMParser().parseFromString(n.svg, "image/svg+xml");
    const svg = document.importNode(doc.documentElement, true);
    if (svg.namespaceURI === SVGNS && svg.localName === "svg") {
      div.append(svg);
      for (const e of svg.querySelectorAll("[data-k]")) {
        (entry.k[+e.getAttribute("data-k")] ||= []).push(e);
      }
      for (const e of svg.querySelectorAll("[data-v]")) entry.v[+e.getAttribute("data-v")] = e;
    }
  } else {
    if (n.why) div.append(el("div", { class: "why" }, "STL: not LAD-representable: " + n.why));
    const table = el("table", { class: "stl" });
    for (const line of n.stl || []) {
      const tr = el("tr");
      tr.append(el("td", {}, line.m));
      const ops = el("td");
      line.ops.forEach((o, i) => {
        if (i) ops.append(document.createTextNode(", "));
        ops.append(el("span", { "data-op": o, class: "op" }, o));
        const val = el("span", { class: "val" });
        entry.v.push(val);
        ops.append(val);
      });
      tr.append(ops, el("td", { class: "cmt" }, line.c ? "// " + line.c : ""));
      table.append(tr);
    }
    div.append(table);
  }
  P.nets[n.id] = entry;
  seen.observe(div);
  return div;
}

// ---------------------------------------------------------------- inputs and outputs
function buildIO(h) {
  const ins = $("inputs");
  ins.replaceChildren();
  resetKinds();
  h.inputs.forEach((io, i) => {
    const wrap = el("div", { class: "io" });
    setKind(io);
    const sw = el("button", { class: "sw", "data-input": io.addr,
                              title: (io.comment || io.addr) + (i < 9 ? " (key " + (i + 1) + ")" : "") },
                  i < 9 ? String(i + 1) : "");
    const kind = el("button", { class: "kind", title: "switch or push-button" });
    const paint = () => {
      const m = P.kinds[io.addr] === "momentary";
      sw.classList.toggle("momentary", m);
      kind.textContent = kindLabel(io.addr);
    };
    paint();
    kind.addEventListener("click", () => {
      P.kinds[io.addr] = P.kinds[io.addr] === "momentary" ? "switch" : "momentary";
      paint();
    });
    sw.addEventListener("pointerdown", (e) => { e.preventDefault(); press(io.addr, true); });
    sw.addEventListener("pointerup", () => press(io.addr, false));
    sw.addEventListener("pointerleave", () => { if (P.pressed[io.addr]) press(io.addr, false); });
    sw.addEventListener("keydown", (e) => {
      if ((e.key === " " || e.key === "Enter") && !e.repeat) { e.preventDefault(); press(io.addr, true); }
    });
    sw.addEventListener("keyup", (e) => {
      if (e.key === " " || e.key === "Enter") { e.preventDefault(); press(io.addr, false); }
    });
    wrap.append(sw, el("span", { class: "name" }, io.name ? io.name.split(":")[0] : ""),
                el("span", {}, io.addr), kind);
    ins.append(wrap);
  });
  const outs = $("outputs");
  outs.replaceChildren();
  for (const io of h.outputs) {
    const wrap = el("div", { class: "io", title: io.comment || io.addr });
    wrap.append(el("div", { class: "lamp", "data-lamp": io.addr }),
                el("span", { class: "name" }, io.name ? io.name.split(":")[0] : ""),
                el("span", {}, io.addr));
    outs.append(wrap);
  }
}

// Input kinds come from the server (the lesson's table or the symbol's
// comment): a switch, or a push-button that rests at 0 (normally open) or
// at 1 (normally closed: held, it reads 0).  A new hello starts afresh.
function resetKinds() { P.kinds = {}; P.pressed = {}; P.rest = {}; }
function setKind(io) {
  const kind = io.kind || "switch";
  P.kinds[io.addr] = kind.startsWith("button") ? "momentary" : "switch";
  P.rest[io.addr] = kind.endsWith("_nc") ? 1 : 0;
}
function kindLabel(addr) {
  if (P.kinds[addr] !== "momentary") return "switch";
  return P.rest[addr] ? "NC push-button" : "push-button";
}

// down: pointer or key pressed on an input
function press(addr, down) {
  if (P.kinds[addr] === "momentary") {
    if (P.pressed[addr] === down) return;
    P.pressed[addr] = down;
    const rest = P.rest[addr] || 0;
    send({ type: "set", addr: addr, value: String(down ? 1 - rest : rest) });
  } else if (down) {
    const now = P.frame ? P.frame.io[addr] : 0;
    send({ type: "set", addr: addr, value: now ? "0" : "1" });
  }
}

document.addEventListener("keydown", (e) => {
  if (e.target.closest && e.target.closest("input, select, textarea, button, [contenteditable], #editor-host, #draw")) return;
  if (e.repeat || e.ctrlKey || e.metaKey || e.altKey) return;
  const n = "123456789".indexOf(e.key);
  if (n >= 0 && P.hello && P.hello.inputs[n]) { press(P.hello.inputs[n].addr, true); return; }
  if (e.key === "r") send({ type: "run" });
  else if (e.key === "s") send({ type: "stop" });
  else if (e.key === "n") send({ type: "step" });
});
document.addEventListener("keyup", (e) => {
  if (e.target.closest && e.target.closest("input, select, textarea, button, [contenteditable], #editor-host, #draw")) return;
  const n = "123456789".indexOf(e.key);
  if (n >= 0 && P.hello && P.hello.inputs[n]) press(P.hello.inputs[n].addr, false);
});

// ---------------------------------------------------------------- frames
function onFrame(f) {
  P.frame = f;
  $("time").textContent = f.t.toFixed(3);
  $("scans").textContent = String(f.scans);
  $("mode").textContent = f.mode;
  $("mode").classList.toggle("stop", f.mode !== "RUN");
  $("runstate").textContent = f.run + (f.paused_at ? " at " + f.paused_at : "") +
    (f.until ? " until " + f.until : "");
  $("runstate").classList.toggle("paused", f.run === "paused");
  $("rate").textContent = f.run === "running" ? "\u00d7" + f.rate.toFixed(1) : "";
  const sp = f.speed.mode === "factor" ? String(f.speed.factor) : f.speed.mode;
  if (document.activeElement !== $("speed") && [...$("speed").options].some((o) => o.value === sp)) {
    $("speed").value = sp;
  }
  for (const [id, st] of Object.entries(f.nets)) {
    const entry = P.nets[id];
    if (!entry) continue;
    for (let i = 0; i < entry.k.length; i++) {
      const c = st.p[i];
      for (const e of entry.k[i] || []) {
        e.classList.toggle("on", c === "1");
        e.classList.toggle("unk", c === "?");
      }
    }
    for (let i = 0; i < entry.v.length; i++) {
      if (entry.v[i]) entry.v[i].textContent = st.v[i] ? (entry.k.length ? st.v[i] : "=" + st.v[i]) : "";
    }
  }
  for (const [id, entry] of Object.entries(P.nets)) {
    entry.bp.classList.toggle("set", f.breaks.includes(id));
    entry.div.classList.toggle("paused", f.paused_at === id);
  }
  for (const sw of document.querySelectorAll("[data-input]")) {
    sw.classList.toggle("on", !!f.io[sw.dataset.input]);
  }
  for (const lamp of document.querySelectorAll("[data-lamp]")) {
    lamp.classList.toggle("on", !!f.io[lamp.dataset.lamp]);
  }
  ariaIO(f);
  renderWatch(f);
  trendFrame(f.trend);
  axesFrame(f);
  if (window.plcrtMachines) window.plcrtMachines.onFrame(f);   // machines.js
}

// ---------------------------------------------------------------- watch table
function renderWatch(f) {
  const body = $("watch-table").tBodies[0];
  const rows = f.watch.map((w) => {
    const key = w.spec + "|" + w.format;
    let tr = body.querySelector('tr[data-key="' + CSS.escape(key) + '"]');
    if (!tr) {
      tr = el("tr", { "data-key": key, "data-watch": w.spec });
      const input = el("input", { type: "text", "aria-label": "new value of " + w.spec });
      const write = el("button", { title: "write once" }, "Write");
      const force = el("button", { title: "force" }, "Force");
      const unforce = el("button", { title: "release the force" }, "Unforce");
      const del = el("button", { title: "remove" }, "\u00d7");
      const addr = w.spec.split(":")[0];
      write.addEventListener("click", () => send({ type: "set", addr: addr, value: input.value }));
      force.addEventListener("click", () => send({ type: "force", addr: addr, value: input.value }));
      unforce.addEventListener("click", () => send({ type: "unforce", addr: addr }));
      del.addEventListener("click", () => send({ type: "unwatch", spec: w.spec }));
      const tools = el("td");
      tools.append(write, force, unforce, del);
      const inTd = el("td");
      inTd.append(input);
      tr.append(el("td", {}, w.spec), el("td", {}, w.format), el("td", { class: "value" }), inTd, tools);
    }
    tr.children[2].textContent = w.value;
    tr.classList.toggle("forced", w.forced);
    return tr;
  });
  const keep = new Set(rows);
  for (const tr of [...body.children]) if (!keep.has(tr)) tr.remove();
  rows.forEach((tr, i) => { if (body.children[i] !== tr) body.insertBefore(tr, body.children[i] || null); });
}

$("watch-add").addEventListener("submit", (e) => {
  e.preventDefault();
  const spec = $("watch-spec").value.trim();
  if (spec) send({ type: "watch", spec: spec, format: $("watch-format").value });
  $("watch-spec").value = "";
});
$("networks").addEventListener("click", (e) => {
  const op = e.target.closest("[data-op]");
  if (op) send({ type: "watch", spec: op.getAttribute("data-op") });
});

// ---------------------------------------------------------------- run controls
$("run").addEventListener("click", () => send({ type: P.frame && P.frame.run === "paused" ? "continue" : "run" }));
$("stop").addEventListener("click", () => send({ type: "stop" }));
$("step").addEventListener("click", () => send({ type: "step", scans: 1 }));
$("stepn").addEventListener("click", () => {
  const n = parseInt($("nscans").value, 10);
  if (n > 0) send({ type: "step", scans: n });
});
$("until").addEventListener("click", () => {
  const c = $("cond").value.trim();
  if (c) send({ type: "until", cond: c });
});
$("speed").addEventListener("change", () => {
  const v = $("speed").value;
  if (v === "realtime" || v === "max") send({ type: "speed", mode: v });
  else send({ type: "speed", mode: "factor", factor: parseFloat(v) });
});
$("reset").addEventListener("click", () => send({ type: "reset" }));

// ---------------------------------------------------------------- trends
function trendFrame(t) {
  const tr = P.trend;
  if (JSON.stringify(t.signals) !== JSON.stringify(tr.signals) || t.start > tr.end) {
    if (t.signals.length) send({ type: "history" });
    tr.signals = t.signals; tr.t = []; tr.v = []; tr.end = t.end;
    if (!t.signals.length) drawTrend();
    return;
  }
  if (t.end > tr.end) {
    // only the samples after the ones held (a history answer may overlap a frame)
    const last = tr.t.length ? tr.t[tr.t.length - 1] : -Infinity;
    let from = 0;
    while (from < t.t.length && t.t[from] <= last) from++;
    tr.t.push(...t.t.slice(from)); tr.v.push(...t.v.slice(from)); tr.end = t.end;
    if (tr.t.length > 20000) { tr.t.splice(0, tr.t.length - 20000); tr.v.splice(0, tr.v.length - 20000); }
    drawTrend();
  }
}

function onTrend(m) {
  P.trend = { signals: m.signals, t: m.t, v: m.v, end: m.end };
  $("trend-signals").value = m.signals.join(" ");
  drawTrend();
}

const COLORS = ["#1565c0", "#c62828", "#2e7d32", "#6a1b9a", "#ef6c00", "#00838f", "#5d4037", "#455a64"];

function drawTrend() {
  const c = $("trend"), g = c.getContext("2d"), tr = P.trend;
  g.fillStyle = "#fff"; g.fillRect(0, 0, c.width, c.height);
  const n = tr.signals.length;
  if (!n || !tr.t.length) return;
  const t0 = tr.t[0], t1 = Math.max(tr.t[tr.t.length - 1], t0 + 1e-6);
  const left = 70, w = c.width - left - 6, lane = (c.height - 14) / n;
  g.font = "11px sans-serif";
  g.save(); g.beginPath(); g.rect(0, 0, c.width, c.height); g.clip();
  for (let s = 0; s < n; s++) {
    const vals = tr.v.map((r) => (typeof r[s] === "number" ? r[s] : NaN));
    const fin = vals.filter((x) => Number.isFinite(x));
    let lo = Math.min(...fin, 0), hi = Math.max(...fin, 1);
    if (hi === lo) hi = lo + 1;
    const y0 = s * lane + 4, h = lane - 8;
    const Y = (v) => y0 + h - ((v - lo) / (hi - lo)) * h;
    g.fillStyle = COLORS[s % COLORS.length];
    g.fillText(tr.signals[s], 2, y0 + h / 2 + 4);
    g.strokeStyle = COLORS[s % COLORS.length]; g.lineWidth = 1.5;
    g.beginPath();
    let prev = null;
    for (let i = 0; i < vals.length; i++) {
      if (!Number.isFinite(vals[i])) { prev = null; continue; }
      const x = left + ((tr.t[i] - t0) / (t1 - t0)) * w, y = Y(vals[i]);
      if (prev === null) g.moveTo(x, y); else { g.lineTo(x, prev); g.lineTo(x, y); }  // steps
      prev = y;
    }
    g.stroke();
  }
  g.restore();
  g.fillStyle = "#555";
  g.fillText(t0.toFixed(2) + " s", left, c.height - 2);
  g.fillText(t1.toFixed(2) + " s", c.width - 60, c.height - 2);
}

$("trend-form").addEventListener("submit", (e) => {
  e.preventDefault();
  const sigs = $("trend-signals").value.split(/[\s,]+/).filter((s) => s);
  send({ type: "trend", signals: sigs });
});

function download(blob, name) {
  const a = el("a", { href: URL.createObjectURL(blob), download: name });
  document.body.append(a); a.click(); a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

function csvCell(s) { return /[",\n]/.test(s) ? '"' + s.replace(/"/g, '""') + '"' : s; }

$("trend-csv").addEventListener("click", () => {
  const tr = P.trend;
  const lines = [["t"].concat(tr.signals).map(csvCell).join(",")];
  tr.t.forEach((t, i) => lines.push([t].concat(tr.v[i]).join(",")));
  download(new Blob([lines.join("\n") + "\n"], { type: "text/csv" }), "trend.csv");
});
$("trend-png").addEventListener("click", () => {
  $("trend").toBlob((b) => download(b, "trend.png"), "image/png");
});

// ---------------------------------------------------------------- axes
function buildAxis(label, marks) {
  const div = el("div", { class: "axis" });
  const cv = el("canvas", { width: 460, height: 46, class: "slide" });
  const info = el("div", { class: "info" });
  div.append(el("div", {}, label), cv, info);
  $("axis-list").append(div);
  return { div, cv, info, marks };
}

function axesFrame(f) {
  if (!P.axisEls || !P.axisEls.length) return;
  const items = f.axes.map((a) => ({ pos: a.mechanical, txt: "position " + a.position + "  speed " +
      a.speed + " Hz  " + a.status + (a.masked ? " (SevOn)" : "") + (a.stf ? " (STF)" : "") }))
    .concat(f.drives.map((d) => ({ pos: d.position, txt: "position " + d.position + "  velocity " +
      d.velocity + "  " + d.state })));
  items.forEach((it, i) => { if (P.axisEls[i]) drawSlide(P.axisEls[i], it); });
  const last = P.axisHist[P.axisHist.length - 1];
  if (last && f.t < last.t) P.axisHist = [];   // power-up reset: the time went back
  P.axisHist.push({ t: f.t, pos: items.map((x) => x.pos),
                    spd: f.axes.map((a) => a.speed).concat(f.drives.map((d) => d.velocity)) });
  if (P.axisHist.length > 600) P.axisHist.shift();
  drawAxisTrend();
}

function drawSlide(ax, it) {
  const m = ax.marks, c = ax.cv, g = c.getContext("2d");
  const pts = [it.pos, m.start, m.limit_neg, m.limit_pos, m.neg_limit, m.pos_limit, m.neg_stop,
               m.pos_stop].concat(m.rps || [], m.home_switch || []).filter((x) => typeof x === "number");
  let lo = Math.min(...pts), hi = Math.max(...pts);
  if (hi - lo < 1000) { lo -= 500; hi += 500; }
  const pad = (hi - lo) * 0.05; lo -= pad; hi += pad;
  ax.lo = lo; ax.hi = hi;
  const X = (v) => 8 + ((v - lo) / (hi - lo)) * (c.width - 16);
  g.fillStyle = "#fff"; g.fillRect(0, 0, c.width, c.height);
  g.fillStyle = "#cfd8dc"; g.fillRect(8, 26, c.width - 16, 6);
  const lim = [m.limit_neg ?? m.neg_limit, m.limit_pos ?? m.pos_limit];
  g.fillStyle = "rgba(198,40,40,0.35)";
  if (typeof lim[0] === "number") g.fillRect(8, 20, X(lim[0]) - 8, 18);
  if (typeof lim[1] === "number") g.fillRect(X(lim[1]), 20, c.width - 8 - X(lim[1]), 18);
  const band = m.rps || m.home_switch;
  if (band) { g.fillStyle = "rgba(46,125,50,0.45)"; g.fillRect(X(band[0]), 20, Math.max(2, X(band[1]) - X(band[0])), 18); }
  const zp = m.z_period || m.index_period, zo = m.z_offset ?? m.index_phase ?? 0;
  if (zp && (hi - lo) / zp < 200) {
    g.strokeStyle = "#6a1b9a";
    for (let z = zo + Math.ceil((lo - zo) / zp) * zp; z <= hi; z += zp) {
      g.beginPath(); g.moveTo(X(z), 36); g.lineTo(X(z), 44); g.stroke();
    }
  }
  const x = X(it.pos);
  g.fillStyle = "#1565c0"; g.fillRect(x - 9, 8, 18, 16);
  g.beginPath(); g.moveTo(x, 24); g.lineTo(x - 5, 30); g.lineTo(x + 5, 30); g.fill();
  ax.info.textContent = it.txt;
  ax.div.dataset.position = String(it.pos);
}

function drawAxisTrend() {
  const c = $("axis-trend"), g = c.getContext("2d"), hist = P.axisHist;
  g.fillStyle = "#fff"; g.fillRect(0, 0, c.width, c.height);
  if (hist.length < 2) return;
  const t0 = hist[0].t, t1 = Math.max(hist[hist.length - 1].t, t0 + 1e-6);
  const series = [["pos", c.height / 2 - 4, 2], ["spd", c.height / 2 - 4, c.height / 2 + 2]];
  g.save(); g.beginPath(); g.rect(0, 0, c.width, c.height); g.clip();
  for (const [key, h, y0] of series) {
    const n = hist[0][key].length;
    for (let s = 0; s < n; s++) {
      const vals = hist.map((p) => p[key][s]);
      let lo = Math.min(...vals), hi = Math.max(...vals);
      if (hi === lo) { hi += 1; lo -= 1; }
      g.strokeStyle = COLORS[(s + (key === "spd" ? 3 : 0)) % COLORS.length];
      g.beginPath();
      hist.forEach((p, i) => {
        const x = 4 + ((p.t - t0) / (t1 - t0)) * (c.width - 8), y = y0 + h - ((p[key][s] - lo) / (hi - lo)) * h;
        if (i) g.lineTo(x, y); else g.moveTo(x, y);
      });
      g.stroke();
    }
    g.fillStyle = "#555"; g.font = "10px sans-serif";
    g.fillText(key === "pos" ? "position" : "speed", 6, y0 + 10);
  }
  g.restore();
}

// ---------------------------------------------------------------- diagnostics
// What `plcrt run` prints on stderr (warnings at load and while running, a
// fault), each with its network: a click shows that network.
function onDiagnostics(d) {
  const ul = $("diags");
  ul.replaceChildren();
  for (const it of d.items) {
    const li = el("li", { class: it.severity });
    const b = el("button", { type: "button", title: it.text });
    const where = it.network ? it.block + " network " + it.network.slice(it.block.length + 1)
      : (it.block || "");
    if (where) b.append(el("span", { class: "where" }, where + ":"), " ");
    b.append(document.createTextNode(it.severity + ": " + it.message +
                                     (it.where ? " (" + it.where + ")" : "")));
    if (it.network) b.dataset.shows = it.network;
    b.addEventListener("click", () => showNetwork(it.network, it.block));
    li.append(b);
    ul.append(li);
  }
  if (d.more) ul.append(el("li", {}, d.more));
}

function showNetwork(id, block) {
  if (block && block !== P.block && P.hello.blocks.some((b) => b.id === block)) showBlock(block);
  for (const e of document.querySelectorAll(".net.flash")) e.classList.remove("flash");
  const entry = id && P.nets[id];
  if (!entry) return;
  entry.div.classList.add("flash");
  entry.div.scrollIntoView({ block: "center" });
}

// ---------------------------------------------------------------- accessibility
// Inputs are switches (role switch, aria-checked) or push-buttons
// (aria-pressed while held), lamps images named "Q0.0 Motor: on"; names
// are the address and the symbol.
function ioLabel(io) { return io.addr + (io.name ? " " + io.name.split(":")[0] : ""); }

function attr(e, name, value) { if (e.getAttribute(name) !== value) e.setAttribute(name, value); }

function ariaIO(f) {
  if (!P.hello) return;
  const io = f ? f.io : {};
  const byAddr = new Map(P.hello.inputs.concat(P.hello.outputs).map((x) => [x.addr, x]));
  for (const sw of document.querySelectorAll("[data-input]")) {
    const x = byAddr.get(sw.dataset.input);
    if (!x) continue;
    attr(sw, "aria-label", ioLabel(x));
    if (P.kinds[x.addr] === "switch") {
      attr(sw, "role", "switch");
      sw.removeAttribute("aria-pressed");
      attr(sw, "aria-checked", String(!!io[x.addr]));
    } else {
      sw.removeAttribute("role");
      sw.removeAttribute("aria-checked");
      attr(sw, "aria-pressed", String(!!P.pressed[x.addr]));
    }
  }
  for (const lamp of document.querySelectorAll("[data-lamp]")) {
    const x = byAddr.get(lamp.dataset.lamp);
    if (!x) continue;
    attr(lamp, "role", "img");
    attr(lamp, "aria-label", ioLabel(x) + ": " + (io[x.addr] ? "on" : "off"));
  }
}
// a switch turned into a push-button (or back) is announced as one at once
$("inputs").addEventListener("click", (e) => { if (e.target.closest(".kind")) ariaIO(P.frame); });

// ---------------------------------------------------------------- the course
function buildLesson(h) {
  const sel = $("lessons");
  sel.replaceChildren();
  sel.hidden = !h.lessons.length;
  for (const l of h.lessons) {
    const o = el("option", { value: l.id }, l.title);
    if (h.lesson && h.lesson.id === l.id) o.selected = true;
    sel.append(o);
  }
  $("lesson").hidden = !h.lesson;
  $("check-results").replaceChildren();
  $("check-output").hidden = true;
  if (!h.lesson) return;
  $("lesson-title").textContent = h.lesson.title;
  $("check").hidden = !h.lesson.checkable;
  $("lesson-text").replaceChildren(renderDoc(h.lesson.doc));
  if (h.load_error) {
    $("lesson-text").prepend(el("pre", { class: "load-error", "data-load-error": "" },
                                h.load_error.message));
  }
}
$("lessons").addEventListener("change", () => {
  // another lesson is another program file: the editor's unsaved edits would go
  const ed = window.plcrtEditor;
  if (ed && ed.dirty() && !window.confirm("Switch lessons and discard your unsaved edits?")) {
    $("lessons").value = P.hello.lesson.id;
    return;
  }
  send({ type: "lesson", id: $("lessons").value });
});
$("check").addEventListener("click", () => {
  $("check").disabled = true;
  $("check-results").replaceChildren(el("li", {}, "running the tests ..."));
  send({ type: "check" });
});

function onCheck(m) {
  $("check").disabled = false;
  const ul = $("check-results");
  ul.replaceChildren(el("li", { class: m.ok ? "passed" : "failed" },
                        m.passed + " passed, " + m.failed + " failed"));
  for (const t of m.tests) {
    ul.append(el("li", { class: t.outcome, "data-test": t.name },
                 (t.outcome === "passed" ? "\u2714 " : "\u2718 ") + t.doc + (t.message ? ": " + t.message : "")));
  }
  $("check-output").textContent = m.output;
  $("check-output").hidden = m.ok;
}

// The lesson text: blocks and spans the server built from its Markdown
// (plcrt/web/markdown.py); every word goes in with textContent, and a link
// only to an http(s) address (new tab, no opener) or a lesson file.
function renderSpans(parent, spans) {
  for (const s of spans || []) {
    let e = document.createTextNode(s.t);
    if (s.code) { const c = el("code"); c.append(e); e = c; }
    if (s.i) { const c = el("em"); c.append(e); e = c; }
    if (s.b) { const c = el("strong"); c.append(e); e = c; }
    if (s.href && /^(https?:\/\/|lesson\/)/.test(s.href)) {
      const a = el("a", { href: s.href, target: "_blank", rel: "noopener noreferrer" });
      a.append(e); e = a;
    }
    parent.append(e);
  }
  return parent;
}

function renderDoc(doc) {
  const out = document.createDocumentFragment();
  for (const b of doc || []) {
    if (b.h !== undefined) out.append(renderSpans(el("h3"), b.s));
    else if (b.p !== undefined) out.append(renderSpans(el("p"), b.p));
    else if (b.pre !== undefined) out.append(el("pre", {}, b.pre));
    else if (b.ul || b.ol) {
      const list = el(b.ul ? "ul" : "ol", b.start ? { start: String(b.start) } : {});
      for (const item of b.ul || b.ol) list.append(renderSpans(el("li"), item));
      out.append(list);
    } else if (b.table) {
      const table = el("table", { class: "md" });
      const head = el("tr");
      for (const c of b.table.head) head.append(renderSpans(el("th"), c));
      table.append(head);
      for (const row of b.table.rows) {
        const tr = el("tr");
        for (const c of row) tr.append(renderSpans(el("td"), c));
        table.append(tr);
      }
      out.append(table);
    }
  }
  return out;
}

connect();

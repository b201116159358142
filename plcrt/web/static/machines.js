// plcrt panel: the plant's machines as SVG animations (docs/panel.md,
// "Machines").  Each frame carries every machine's state() (cleaned by
// plcrt/web/machines.py: numbers, booleans, short names); this file draws
// them with createElementNS and textContent only, never innerHTML.  The
// buttons and the teacher's fault switches send the "machine" message.
"use strict";

(function () {
  const SVGNS = "http://www.w3.org/2000/svg";
  const M = { cards: {} };
  window.plcrtMachines = M;

  function send(msg) {
    const P = window.plcrtPanel;
    if (P && P.ws && P.ws.readyState === WebSocket.OPEN) P.ws.send(JSON.stringify(msg));
  }

  // An SVG element with attributes (and text), appended to parent.
  function s(parent, tag, attrs, text) {
    const e = document.createElementNS(SVGNS, tag);
    for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, String(v));
    if (text !== undefined) e.textContent = String(text);
    if (parent) parent.append(e);
    return e;
  }
  function h(tag, attrs, text) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === "class") e.className = v; else e.setAttribute(k, v);
    }
    if (text !== undefined) e.textContent = String(text);
    return e;
  }
  const num = (v, d) => (typeof v === "number" && isFinite(v) ? v : (d || 0));
  const on = (v) => v === true || v === 1;
  // a signal with a fault of its own (stuck_on:eye_entry ...) is drawn faulty
  const faulty = (st, sig) => (st.faults || []).some((f) => f.endsWith(":" + sig));
  function mark(e, st, sig, lit) {
    e.classList.toggle("lit", lit);
    e.classList.toggle("faulty", faulty(st, sig));
  }

  // ------------------------------------------------------------ conveyor
  // Belt from x=10 to x=410 (the belt's length scaled); parts stand on it.
  function conveyor(svg) {
    s(svg, "rect", { x: 6, y: 100, width: 408, height: 14, rx: 7, class: "belt" });
    const stripes = s(svg, "line", { x1: 10, y1: 107, x2: 410, y2: 107, class: "stripes" });
    const parts = s(svg, "g", {});
    const gate = s(svg, "rect", { width: 6, height: 44, class: "gate" });
    const divert = s(svg, "line", { class: "divert" });
    const eyes = s(svg, "g", {});
    const bins = s(svg, "text", { x: 10, y: 140, class: "mtext" });
    const byId = new Map();
    const eyeEls = {};
    return (st) => {
      const k = 400 / Math.max(1, num(st.length, 2000));
      const X = (mm) => 10 + mm * k;
      stripes.setAttribute("stroke-dashoffset", String(-((num(st.t) * num(st.speed)) * k) % 20));
      const alive = new Set();
      for (const p of st.parts || []) {
        if (!p || typeof p.id !== "number") continue;
        alive.add(p.id);
        let r = byId.get(p.id);
        if (!r) { r = s(parts, "rect", { "data-part": p.id }); byId.set(p.id, r); }
        const tall = p.kind === "tall";
        const hgt = tall ? 44 : 24;
        // the part still in the feeder (x < part) shows only what is on the belt
        const left = Math.max(0, num(p.x) - num(st.part, 100));
        r.setAttribute("x", X(left).toFixed(2));
        r.setAttribute("y", String(100 - hgt));
        r.setAttribute("width", (Math.max(0, num(p.x) - left) * k).toFixed(2));
        r.setAttribute("height", String(hgt));
        r.setAttribute("class", "part " + (tall ? "tall" : "short") + (p.jammed ? " jammed" : ""));
      }
      for (const [id, r] of byId) if (!alive.has(id)) { r.remove(); byId.delete(id); }
      const gx = X(num(st.gate_at, 1000));
      const open = on((st.outputs || {}).gate);
      gate.setAttribute("x", (gx - 3).toFixed(2));
      gate.setAttribute("y", open ? "20" : "56");
      gate.setAttribute("class", "gate" + (open ? " open" : ""));
      const dx = X(num(st.divert_at, 1500));
      const dv = on((st.outputs || {}).divert);
      divert.setAttribute("x1", dx.toFixed(2)); divert.setAttribute("y1", "98");
      divert.setAttribute("x2", (dx + (dv ? 40 : 0)).toFixed(2));
      divert.setAttribute("y2", dv ? "60" : "78");
      divert.setAttribute("class", "divert" + (dv ? " on" : ""));
      for (const [name, at] of Object.entries(st.eyes || {})) {
        let e = eyeEls[name];
        if (!e) {
          e = eyeEls[name] = s(eyes, "circle", { r: 5, "data-eye": name, class: "eye" });
          s(e, "title", {}, name);
        }
        e.setAttribute("cx", X(num(at)).toFixed(2));
        e.setAttribute("cy", name === "eye_tall" ? "62" : "88");
        mark(e, st, name, on((st.inputs || {})[name]));
      }
      const b = st.bins || {};
      bins.textContent = "straight " + num(b.straight_tall) + " tall, " + num(b.straight_short) +
        " short; diverted " + num(b.diverted_tall) + " tall, " + num(b.diverted_short) + " short";
    };
  }

  // ------------------------------------------------------------ tank
  function tank(svg) {
    s(svg, "rect", { x: 150, y: 20, width: 120, height: 110, class: "vessel" });
    const water = s(svg, "rect", { x: 151, width: 118, class: "water" });
    const inlet = s(svg, "rect", { x: 100, y: 14, width: 30, height: 12, class: "valve" });
    s(svg, "text", { x: 60, y: 24, class: "mtext" }, "inlet");
    const outlet = s(svg, "rect", { x: 290, y: 124, width: 30, height: 12, class: "valve" });
    s(svg, "text", { x: 330, y: 134, class: "mtext" }, "outlet");
    const pump = s(svg, "circle", { cx: 305, cy: 100, r: 10, class: "pump" });
    s(svg, "text", { x: 330, y: 104, class: "mtext" }, "pump");
    const high = s(svg, "circle", { cx: 140, r: 5, class: "eye", "data-eye": "high" });
    const low = s(svg, "circle", { cx: 140, r: 5, class: "eye", "data-eye": "low" });
    const txt = s(svg, "text", { x: 10, y: 145, class: "mtext" });
    return (st) => {
      const cap = Math.max(1, num(st.capacity, 100000));
      const fill = Math.min(1, Math.max(0, num(st.fill)));
      water.setAttribute("y", (130 - 110 * fill).toFixed(2));
      water.setAttribute("height", (110 * fill).toFixed(2));
      const o = st.outputs || {}, i = st.inputs || {};
      inlet.classList.toggle("on", on(o.inlet));
      outlet.classList.toggle("on", on(o.outlet));
      pump.classList.toggle("on", on(o.pump));
      high.setAttribute("cy", (130 - 110 * num(st.high_at) / cap).toFixed(2));
      low.setAttribute("cy", (130 - 110 * num(st.low_at) / cap).toFixed(2));
      mark(high, st, "high", on(i.high));
      mark(low, st, "low", on(i.low));
      txt.textContent = "level " + num(i.level) + "  flow " + num(i.flow) + "  volume " +
        Math.round(num(st.volume)) + " mL";
    };
  }

  // ------------------------------------------------------------ traffic
  function traffic(svg) {
    const lamps = {};
    const head = (road, x) => {
      s(svg, "rect", { x: x, y: 10, width: 30, height: 90, rx: 6, class: "housing" });
      s(svg, "text", { x: x - 4, y: 116, class: "mtext" }, road);
      ["red", "yellow", "green"].forEach((c, n) => {
        lamps[road + "_" + c] = s(svg, "circle", { cx: x + 15, cy: 26 + 29 * n, r: 11,
          class: "tl " + c, "data-lamp": road + "_" + c });
      });
    };
    head("main", 40);
    head("side", 140);
    s(svg, "rect", { x: 240, y: 30, width: 60, height: 60, rx: 6, class: "housing" });
    lamps.walk = s(svg, "circle", { cx: 258, cy: 60, r: 11, class: "tl green", "data-lamp": "walk" });
    lamps.dont_walk = s(svg, "circle", { cx: 282, cy: 60, r: 11, class: "tl red",
      "data-lamp": "dont_walk" });
    s(svg, "text", { x: 240, y: 116, class: "mtext" }, "walk");
    const txt = s(svg, "text", { x: 10, y: 140, class: "mtext" });
    return (st) => {
      const l = st.lamps || {};
      for (const [name, e] of Object.entries(lamps)) e.classList.toggle("lit", on(l[name]));
      const q = st.queue || {};
      txt.textContent = "queue main " + num(q.main) + ", side " + num(q.side) +
        (st.conflict ? "  CONFLICT" : "") + "  conflicts " + num(st.conflicts);
    };
  }

  // ------------------------------------------------------------ garage
  function garage(svg) {
    s(svg, "rect", { x: 100, y: 10, width: 160, height: 120, class: "frame" });
    const door = s(svg, "rect", { x: 102, y: 12, width: 156, class: "door" });
    const obstacle = s(svg, "rect", { x: 160, width: 40, class: "obstacle" });
    const lo = s(svg, "circle", { cx: 280, cy: 20, r: 5, class: "eye", "data-eye": "limit_open" });
    const lc = s(svg, "circle", { cx: 280, cy: 124, r: 5, class: "eye", "data-eye": "limit_closed" });
    const edge = s(svg, "circle", { cx: 90, r: 5, class: "eye", "data-eye": "safety_edge" });
    const lamp = s(svg, "circle", { cx: 60, cy: 20, r: 9, class: "tl yellow" });
    const txt = s(svg, "text", { x: 10, y: 145, class: "mtext" });
    return (st) => {
      const open = Math.min(1, Math.max(0, num(st.open)));
      const hgt = 116 * (1 - open);
      door.setAttribute("height", Math.max(1, hgt).toFixed(2));
      edge.setAttribute("cy", (12 + hgt).toFixed(2));
      const oh = 116 * num(st.obstacle_at) / Math.max(1, num(st.travel, 2400));
      obstacle.setAttribute("y", (128 - oh).toFixed(2));
      obstacle.setAttribute("height", oh.toFixed(2));
      obstacle.style.display = st.obstacle ? "" : "none";
      const i = st.inputs || {};
      mark(lo, st, "limit_open", on(i.limit_open));
      mark(lc, st, "limit_closed", on(i.limit_closed));
      mark(edge, st, "safety_edge", on(i.safety_edge));
      lamp.classList.toggle("lit", on(st.lamp));
      txt.textContent = "door open " + Math.round(num(st.opening)) + " mm, " +
        (num(st.velocity) > 0 ? "opening" : num(st.velocity) < 0 ? "closing" : "still");
    };
  }

  // ------------------------------------------------------------ elevator
  function elevator(svg) {
    s(svg, "rect", { x: 150, y: 5, width: 80, height: 140, class: "frame" });
    const sensors = [];
    for (let n = 1; n <= 3; n++) {
      const y = 140 - (n - 1) * 60;
      s(svg, "line", { x1: 130, y1: y, x2: 250, y2: y, class: "floorline" });
      s(svg, "text", { x: 100, y: y - 4, class: "mtext" }, "floor " + n);
      sensors.push(s(svg, "circle", { cx: 260, cy: y - 6, r: 5, class: "eye",
        "data-eye": "floor_" + n }));
    }
    const car = s(svg, "g", { class: "car" });
    s(car, "rect", { x: 160, y: 0, width: 60, height: 40, class: "cabin" });
    const doorL = s(car, "rect", { y: 2, height: 36, class: "door" });
    const doorR = s(car, "rect", { y: 2, height: 36, class: "door" });
    const txt = s(svg, "text", { x: 280, y: 30, class: "mtext" });
    return (st) => {
      const k = 120 / Math.max(1, 2 * num(st.floor_height, 3000));
      const y = 140 - num(st.car) * k - 40;
      car.setAttribute("transform", "translate(0 " + y.toFixed(2) + ")");
      const w = 29 * (1 - Math.min(1, Math.max(0, num(st.door))));
      doorL.setAttribute("x", "161"); doorL.setAttribute("width", w.toFixed(2));
      doorR.setAttribute("x", (219 - w).toFixed(2)); doorR.setAttribute("width", w.toFixed(2));
      const i = st.inputs || {};
      sensors.forEach((e, n) => mark(e, st, "floor_" + (n + 1), on(i["floor_" + (n + 1)])));
      txt.textContent = "floor " + (num(st.floor) || "-") + (st.moving ? "  moving" : "");
    };
  }

  const KINDS = { conveyor, tank, traffic, garage, elevator };
  // buttons that stay where they are put (a key switch, an obstacle)
  const TOGGLES = new Set(["key", "obstacle"]);

  function buttonFor(name, machine) {
    const b = h("button", { type: "button", "data-button": name }, name);
    if (TOGGLES.has(name)) {
      b.setAttribute("aria-pressed", "false");
      b.addEventListener("click", () => {
        const now = b.getAttribute("aria-pressed") !== "true";
        b.setAttribute("aria-pressed", String(now));
        send({ type: "machine", machine: machine, action: now ? "hold" : "release", name: name });
      });
      return b;
    }
    // a press is 0.3 s of simulated time, so a short click is seen by the
    // scan; kept down longer it is held until let go
    let timer = null, held = false;
    const down = () => {
      send({ type: "machine", machine: machine, action: "press", name: name });
      timer = setTimeout(() => {
        held = true;
        send({ type: "machine", machine: machine, action: "hold", name: name });
      }, 300);
    };
    const up = () => {
      clearTimeout(timer);
      timer = null;
      if (held) send({ type: "machine", machine: machine, action: "release", name: name });
      held = false;
    };
    b.addEventListener("pointerdown", down);
    b.addEventListener("pointerup", up);
    b.addEventListener("pointerleave", () => { if (timer || held) up(); });
    b.addEventListener("keydown", (e) => { if ((e.key === "Enter" || e.key === " ") && !e.repeat) { e.preventDefault(); down(); } });
    b.addEventListener("keyup", (e) => { if (e.key === "Enter" || e.key === " ") up(); });
    return b;
  }

  function card(info) {
    const div = h("div", { class: "machine", "data-machine": info.name });
    div.append(h("h3", {}, info.name + " (" + info.kind + ")"));
    const svg = s(null, "svg", { viewBox: "0 0 420 150", class: "machine-svg " + info.kind,
      role: "img", "aria-label": info.kind + " " + info.name });
    div.append(svg);
    const faultText = h("div", { class: "machine-faults" });
    div.append(faultText);
    const bar = h("div", { class: "machine-buttons" });
    for (const b of info.buttons || []) bar.append(buttonFor(b, info.name));
    div.append(bar);
    const det = h("details", { class: "machine-teacher" });
    det.append(h("summary", {}, "Faults (teacher)"));
    const list = h("ul", {});
    const boxes = {};
    for (const f of info.faults || []) {
      const li = h("li", {});
      const label = h("label", {});
      const box = h("input", { type: "checkbox", "data-fault": f });
      box.addEventListener("change", () => send({ type: "machine", machine: info.name,
        action: box.checked ? "fault_on" : "fault_off", name: f }));
      boxes[f] = box;
      label.append(box, document.createTextNode(" " + f));
      li.append(label);
      list.append(li);
    }
    det.append(list);
    div.append(det);
    const draw = (KINDS[info.kind] || (() => () => {}))(svg);
    return { div, faultText, boxes, draw: (st) => {
      draw(st);
      const active = st.faults || [];
      faultText.textContent = active.length ? "faults: " + active.join(", ") : "";
      div.classList.toggle("has-fault", active.length > 0);
      for (const [f, box] of Object.entries(boxes)) {
        if (document.activeElement !== box) box.checked = active.includes(f);
      }
    } };
  }

  M.onHello = function (hello) {
    const list = document.getElementById("machine-list");
    const infos = hello.machines || [];
    M.cards = {};
    list.replaceChildren();
    for (const info of infos) {
      const c = card(info);
      M.cards[info.name] = c;
      list.append(c.div);
    }
    document.getElementById("machines").hidden = infos.length === 0;
  };

  M.onFrame = function (f) {
    for (const st of f.machines || []) {
      const c = st && M.cards[st.name];
      if (c) c.draw(st);
    }
  };

  // a hello (and frame) that came before this deferred script ran
  const P = window.plcrtPanel;
  if (P && P.hello) {
    M.onHello(P.hello);
    if (P.frame) M.onFrame(P.frame);
  }
})();

// plcrt panel: drawing a network as ladder (docs/panel.md, "Drawing ladder").
// One network of the editor's text is drawn from the server's ladder model
// (/ladder/open); each change is one edit operation sent to /ladder/edit
// (undo and redo to /ladder/undo, /ladder/redo), and the server's answer,
// the editor's text with the network written back as STL, replaces the
// editor's text: Save and Download of the editor apply the drawing.
// Program text is only ever put into the page as textContent or an input's
// value, never as HTML.
"use strict";

(function () {
  const $ = (id) => document.getElementById(id);
  const L = {
    id: null, block: null, number: null, model: null, sel: null, pending: null,
    busy: false, asking: null, queue: Promise.resolve(),   // busy: a change is on its way
  };
  window.plcrtLadder = L;   // for the tests and the curious

  // what a palette entry adds: the element, its operands as typed by
  // default, and whether it goes among the logic (a contact) or the outputs
  const CONTACTS = {
    NO: { el: "NO", ops: "I0.0" }, NC: { el: "NC", ops: "I0.0" },
    P: { el: "P" }, N: { el: "N" }, NOT: { el: "NOT" },
    CMP: { el: "CMP", cmp: "W>=", ops: "VW0, +0" },
  };
  const COILS = {
    "=": { ops: "Q0.0" }, S: { ops: "Q0.0, 1" }, R: { ops: "Q0.0, 1" }, "=I": { ops: "Q0.0" },
  };
  const BOXES = {
    TON: "T37, +10", TOF: "T38, +10", TONR: "T1, +10", CTU: "C0, +10", CTD: "C0, +10",
    MOVB: "VB0, VB1", MOVW: "+0, VW0", MOVD: "+0, VD0", MOVR: "0.0, VD0",
    "+I": "+1, VW0", "-I": "+1, VW0", "*I": "+2, VW0", "/I": "+2, VW0",
    "+D": "+1, VD0", "-D": "+1, VD0", "+R": "1.0, VD0", "-R": "1.0, VD0",
    INCW: "VW0", DECW: "VW0", CALL: "SBR0",
  };
  const COUNTERS = new Set(["CTU", "CTD"]);
  // the keys of the palette (also on its buttons' titles)
  const KEYS = { c: "NO", "/": "NC", "?": "NC", "=": "=", "+": "=", p: "P", n: "N", t: "NOT", m: "CMP", o: "BRANCH",
    q: "=", s: "S", r: "R", i: "=I", b: "BOX" };
  const SYMBOL = { NO: "\u2524 \u251c", NC: "\u2524/\u251c", NOI: "\u2524I\u251c",
    NCI: "\u2524/I\u251c", P: "\u2524P\u251c", N: "\u2524N\u251c", NOT: "\u2524NOT\u251c" };

  // ------------------------------------------------------------- server
  // a POST of JSON, answered with JSON (editor.js's; the editor loads first)
  const api = (route, body) => window.plcrtEditor.api(route, body);

  function status(text, level) {
    const s = $("draw-status");
    s.textContent = text;
    s.className = level || "";
  }

  function editorText() { return window.plcrtEditor.view.state.doc.toString(); }

  function setEditorText(text) {
    const v = window.plcrtEditor.view;
    const old = v.state.doc.toString();
    // replace only what changed (the network): the rest of the document,
    // its undo history and the reader's place stay
    let a = 0;
    while (a < old.length && a < text.length && old[a] === text[a]) a += 1;
    let b = 0;
    while (b < old.length - a && b < text.length - a &&
           old[old.length - 1 - b] === text[text.length - 1 - b]) b += 1;
    v.dispatch({ changes: { from: a, to: old.length - b, insert: text.slice(a, text.length - b) } });
  }

  // ------------------------------------------------------------- networks
  async function listNetworks() {
    const ans = await api("/ladder/networks", { text: editorText() });
    const sel = $("draw-net");
    const keep = sel.value;
    sel.replaceChildren();
    if (!ans.ok) { status(ans.message || "the program cannot be read", "error"); return; }
    for (const n of ans.networks) {
      const o = document.createElement("option");
      o.value = n.block + "/" + n.number;
      o.textContent = (n.name || n.block) + " network " + n.number + (n.title ? ": " + n.title : "") +
        (n.drawable ? "" : " (STL)");
      sel.append(o);
    }
    if ([...sel.options].some((o) => o.value === keep)) sel.value = keep;
  }

  async function open() {
    const [block, number] = $("draw-net").value.split("/");
    if (!block) return;
    L.pending = null;
    const ans = await api("/ladder/open", { text: editorText(), block, number: Number(number) });
    $("draw").hidden = false;
    if (!ans.ok) { status(ans.message, "error"); return; }
    L.block = block; L.number = Number(number);
    L.id = ans.id || null;
    L.model = ans.ladder;
    L.sel = null;
    show(ans);
    if (ans.ladder === null) {
      status("this network stays STL: " + ans.reason, "warning");
    } else {
      status("drawing " + block + " network " + number, "ok");
      $("draw-rung").focus();
    }
  }

  // an empty network after the last one of the chosen network's block,
  // drawn at once
  async function newNetwork() {
    await listNetworks();
    const block = ($("draw-net").value || "OB1/").split("/")[0];
    const ans = await api("/ladder/new", { text: editorText(), block });
    if (!ans.ok) { status(ans.message || "refused", "error"); $("draw").hidden = false; return; }
    setEditorText(ans.text);
    await listNetworks();
    $("draw-net").value = ans.block + "/" + ans.number;
    await open();
  }

  function show(ans) {
    $("draw-stl").textContent = ans.stl;
    $("draw-palette").hidden = ans.ladder === null;
    $("draw-undo").disabled = !ans.undo;
    $("draw-redo").disabled = !ans.redo;
    render();
  }

  // one request at a time, in the order asked (keys pressed quickly, such
  // as Ctrl+Z Ctrl+Z, all count)
  function send(route, extra) {
    const next = L.queue.then(() => sendNow(route, extra));
    L.queue = next.catch(() => false);
    return next;
  }

  async function sendNow(route, extra) {
    if (!L.id) return false;
    L.busy = true;
    const before = sigs();
    const ans = await api(route, Object.assign({ id: L.id, text: editorText() }, extra));
    L.busy = false;
    if (!ans.ok) { status(ans.message || "refused", "error"); return false; }
    setEditorText(ans.text);
    L.model = ans.ladder;
    L.pending = null;
    show(ans);
    // select what the operation made: the first element that differs
    const after = sigs();
    let k = 0;
    while (k < after.length && k < before.length && after[k] === before[k]) k += 1;
    const els = elements();
    const pick = els[Math.min(k, els.length - 1)] || null;
    L.sel = pick ? pick.dataset.path : null;
    mark();
    status(route === "/ladder/edit" ? "done" : route.slice(8) + " done", "ok");
    $("draw-rung").focus();
    return true;
  }

  const edit = (op) => send("/ladder/edit", { op });

  // ------------------------------------------------------------- drawing
  function div(cls, text) {
    const d = document.createElement("div");
    d.className = cls;
    if (text !== undefined) d.textContent = text;
    return d;
  }

  function leaf(kind, path, x, top, sym, bottom) {
    const d = div("lad-el " + kind);
    d.dataset.path = JSON.stringify(path);
    d.dataset.kind = kind === "contact" ? "logic" : "out";
    d.dataset.sig = JSON.stringify(x);
    d.append(div("lad-op", top || "\u00a0"), div("lad-sym", sym), div("lad-op", bottom || "\u00a0"));
    d.setAttribute("role", "button");
    d.draggable = true;
    d.setAttribute("aria-label", (x.insn || x.el) + " " + (x.ops || []).join(", "));
    return d;
  }

  function logic(x, path) {
    if (x.el === "series") {
      const d = div("lad-series");
      x.items.forEach((it, k) => d.append(logic(it, path.concat(k))));
      return d;
    }
    if (x.el === "parallel") {
      const d = div("lad-par");
      x.items.forEach((it, k) => {
        const b = div("lad-branch");
        b.append(logic(it, path.concat(k)));
        d.append(b);
      });
      return d;
    }
    if (x.el === "CMP") return leaf("contact", path, x, x.ops[0], "\u2524" + x.cmp + "\u251c", x.ops[1]);
    return leaf("contact", path, x, (x.ops || [])[0], SYMBOL[x.el] || x.el);
  }

  function out(x, path) {
    if (x.el === "node") return node(x, path);
    if (x.el === "coil") {
      const sym = "(" + (x.insn === "=" ? " " : x.insn === "=I" ? "I" : x.insn) + ")";
      return leaf("coil", path, x, x.ops[0], sym, x.ops[1]);
    }
    const box = leaf("box", path, x, null, x.lad || x.insn, null);
    const pins = div("lad-pins");
    for (const p of x.pins || []) {
      if (p.op === undefined) continue;
      const name = p.place === "above" ? "" : (p.name || "") + " ";
      pins.append(div("lad-pin", name + (x.ops[p.op] === undefined ? "" : x.ops[p.op])));
    }
    box.insertBefore(pins, box.lastChild);
    if (!x.inputs || !x.inputs.length) {
      if (!x.next) return box;
      const row = div("lad-series");
      row.append(box, node(x.next, path.concat("next")));
      return row;
    }
    const row = div("lad-series");
    const ins = div("lad-par");
    x.inputs.forEach((it, k) => {
      const b = div("lad-branch");
      b.append(logic(it, path.concat("inputs", k)));
      ins.append(b);
    });
    row.append(ins, box);
    return row;
  }

  function node(x, path) {
    const d = div("lad-node");
    if (x.logic) d.append(logic(x.logic, path.concat("logic")));
    const outs = div("lad-outs");
    x.outs.forEach((o, k) => outs.append(out(o, path.concat("outs", k))));
    d.append(outs);
    return d;
  }

  function render() {
    const host = $("draw-rung");
    host.replaceChildren();
    if (!L.model) return;
    const rail = div("lad-rail");
    if (L.model.rung) {
      rail.append(L.model.rung.el === "node" ? node(L.model.rung, ["rung"])
        : out(L.model.rung, ["rung"]));
    } else if (L.pending) {
      const d = div("lad-node");
      d.append(logic(L.pending, ["pending"]));
      d.append(div("lad-hint", "add an output: a coil or a box"));
      rail.append(d);
    } else {
      rail.append(div("lad-hint", "empty network: add a contact (or a counter) to start a rung"));
    }
    host.append(rail);
    mark();
  }

  const elements = () => [...$("draw-rung").querySelectorAll(".lad-el")];
  const sigs = () => elements().map((e) => e.dataset.sig);

  function mark() {
    for (const e of elements()) e.classList.toggle("selected", e.dataset.path === L.sel);
  }

  function selected() {
    return elements().find((e) => e.dataset.path === L.sel) || null;
  }

  // ------------------------------------------------------------- operands
  // an input in place of (or after) an element; Enter gives its text,
  // Escape gives up
  function ask(anchor, label, value, done) {
    cancelAsk();
    const input = document.createElement("input");
    input.type = "text";
    input.className = "lad-input";
    input.value = value;
    input.setAttribute("aria-label", label);
    input.maxLength = 600;
    input.addEventListener("keydown", async (e) => {
      if (e.key === "Enter") {
        e.preventDefault();
        e.stopPropagation();
        const text = input.value;
        L.asking = null;
        input.remove();
        await done(text);
      } else if (e.key === "Escape") {
        e.preventDefault();
        e.stopPropagation();
        cancelAsk();
        $("draw-rung").focus();
      }
    });
    if (anchor) anchor.after(input); else $("draw-rung").append(input);
    L.asking = input;
    input.focus();
    input.select();
  }

  function cancelAsk() {
    if (L.asking) { L.asking.remove(); L.asking = null; }
  }

  const opsOf = (text) => text.split(",").map((s) => s.trim()).filter((s) => s !== "");

  function editOperands() {
    const e = selected();
    if (!e) return;
    const x = JSON.parse(e.dataset.sig);
    if (!x.ops || !x.ops.length) { status("this element has no operand", "warning"); return; }
    ask(e, "operands of " + (x.insn || x.el), x.ops.join(", "),
      (text) => edit({ op: "operands", at: JSON.parse(L.sel), ops: opsOf(text) }));
  }

  // ------------------------------------------------------------- adding
  // the node the selection belongs to (its path), and where an output goes
  function nodeOf(path) {
    for (let k = path.length - 1; k >= 0; k -= 1) {
      if (path[k] === "logic" || path[k] === "outs") return path.slice(0, k);
    }
    return ["rung"];
  }

  function addContact(kind) {
    const spec = CONTACTS[kind];
    const make = (text) => {
      const el = { el: spec.el };
      if (spec.cmp) el.cmp = spec.cmp;
      if (spec.ops) el.ops = opsOf(text);
      return el;
    };
    const anchor = selected();
    const go = (text) => {
      const el = make(text);
      if (!L.model.rung) {   // a new rung: its output comes next
        if (!el.ops) { status("a rung starts with a contact from the rail", "error"); return; }
        L.pending = el;
        render();
        status("add an output: a coil or a box", "ok");
        $("draw-rung").focus();
        return;
      }
      const path = L.sel ? JSON.parse(L.sel) : null;
      if (path && anchor && anchor.dataset.kind === "logic") {
        return edit({ op: "insert", at: path, side: "after", element: el });
      }
      const at = nodeOf(path || ["rung", "outs", 0]).concat("logic");
      return edit({ op: "insert", at, side: "after", element: el });
    };
    if (!spec.ops) { go(""); return; }
    ask(anchor, "operand of the new " + kind + " contact", spec.ops, go);
  }

  function addBranch() {
    const e = selected();
    if (!e || e.dataset.kind !== "logic") {
      status("select a contact to put a parallel branch around", "warning");
      return;
    }
    ask(e, "operand of the parallel contact", "I0.0", (text) =>
      edit({ op: "parallel", at: JSON.parse(L.sel), branch: { el: "NO", ops: opsOf(text) } }));
  }

  function addOutput(insn, box) {
    const anchor = selected();
    const defaults = box ? BOXES[insn] : COILS[insn].ops;
    ask(anchor, "operands of the new " + insn, defaults, (text) => {
      const el = box ? { el: "box", insn, ops: opsOf(text) } : { el: "coil", insn, ops: opsOf(text) };
      if (box && COUNTERS.has(insn)) {
        if (L.model.rung) { status("a counter is a rung of its own: draw it in an empty network", "error"); return; }
        el.inputs = [{ el: "NO", ops: ["I0.0"] }, { el: "NO", ops: ["I0.1"] }];
        return edit({ op: "replace", at: ["rung"], element: el });
      }
      if (!L.model.rung) {
        if (!L.pending) { status("add a contact first: a rung starts with one", "error"); return; }
        return edit({ op: "replace", at: ["rung"], element: { el: "node", logic: L.pending, outs: [el] } });
      }
      const path = L.sel ? JSON.parse(L.sel) : ["rung", "logic"];
      const k = path.lastIndexOf("outs");
      if (anchor && anchor.dataset.kind === "out" && k >= 0 && typeof path[k + 1] === "number") {
        return edit({ op: "output", at: path.slice(0, k), index: path[k + 1] + 1, element: el });
      }
      return edit({ op: "output", at: nodeOf(path), element: el });
    });
  }

  // Shift with a palette entry: the selected element becomes that kind,
  // keeping its operands where it has as many (NO -> NC, = -> S)
  function change(what) {
    const e = selected();
    if (!e) { status("select the element to change", "warning"); return; }
    const x = JSON.parse(e.dataset.sig);
    const at = JSON.parse(L.sel);
    let el = null;
    if (CONTACTS[what] && e.dataset.kind === "logic") {
      const spec = CONTACTS[what];
      el = { el: spec.el };
      if (spec.cmp) el.cmp = spec.cmp;
      if (spec.ops) {
        const want = opsOf(spec.ops);
        el.ops = x.ops && x.ops.length === want.length ? x.ops : want;
      }
    } else if (COILS[what] && x.el === "coil") {
      const want = opsOf(COILS[what].ops);
      el = { el: "coil", insn: what, ops: want.map((d, k) => (x.ops[k] === undefined ? d : x.ops[k])) };
    }
    if (!el) { status("a contact changes into a contact, a coil into a coil", "warning"); return; }
    edit({ op: "replace", at, element: el }).then((ok) => { if (ok) { L.sel = JSON.stringify(at); mark(); } });
  }

  // Alt with left or right: the selected element moves one place in its
  // series (a contact) or among its node's outputs
  function shift(dir) {
    if (!L.sel) return;
    const at = JSON.parse(L.sel);
    const k = at[at.length - 1];
    if (typeof k !== "number") { status("this element has no neighbour to swap with", "warning"); return; }
    const parentPath = at.slice(0, -1);
    let parent = L.model;
    for (const step of parentPath) parent = typeof step === "number" ? (parent.items || parent)[step] : parent[step];
    const items = Array.isArray(parent) ? parent : parent.items;
    const j = k + dir;
    if (!items || j < 0 || j >= items.length) return;
    let op;
    if (parentPath[parentPath.length - 1] === "outs") {
      op = { op: "move", from: at, to: parentPath.slice(0, -1), index: j };
    } else if (parent.el === "series") {
      // after the deletion the series is one shorter (or, of two, the one left)
      const to = items.length === 2 ? parentPath : parentPath.concat(Math.min(j, k));
      op = { op: "move", from: at, to, side: dir > 0 ? "after" : "before" };
    } else {
      status("a parallel branch's elements are moved with Delete and adding", "warning");
      return;
    }
    const els = elements();
    const sig = selected().dataset.sig;
    const before = els.indexOf(selected());
    edit(op).then((ok) => {
      if (!ok) return;
      // the moved element: the nearest one that is it, in the direction moved
      const now = elements();
      const same = now.filter((e) => e.dataset.sig === sig);
      const pick = same.sort((a, b) => Math.abs(now.indexOf(a) - before - dir) -
        Math.abs(now.indexOf(b) - before - dir))[0];
      if (pick) { L.sel = pick.dataset.path; mark(); }
    });
  }

  // the mouse: an element dragged onto another goes before or after it
  // (the side of the target it is dropped on); a contact among contacts,
  // a coil or box among outputs.  The target's path is given as it is
  // after the dragged element is deleted (the model's move operation).
  function valueAt(path) {
    let x = L.model;
    for (const step of path) x = typeof step === "number" ? (x.items || x)[step] : x[step];
    return x;
  }

  function afterDelete(from, path) {
    const p = from.slice(0, -1);
    const k = from[from.length - 1];
    const parent = valueAt(p);
    const same = path.length > p.length && p.every((s, i) => s === path[i]);
    if (!same || typeof path[p.length] !== "number") return path;
    const j = path[p.length];
    if (parent && parent.items && parent.items.length === 2) {
      // a series or parallel of two is left as the other element alone
      return p.concat(path.slice(p.length + 1));
    }
    return j > k ? p.concat(j - 1, path.slice(p.length + 1)) : path;
  }

  function drop(fromEl, ontoEl, right) {
    const from = JSON.parse(fromEl.dataset.path);
    const onto = JSON.parse(ontoEl.dataset.path);
    if (fromEl === ontoEl || onto[0] === "pending") return;
    if (fromEl.dataset.kind !== ontoEl.dataset.kind) {
      status("a contact goes among contacts, a coil or box among outputs", "warning");
      return;
    }
    const sig = fromEl.dataset.sig;
    let op;
    if (fromEl.dataset.kind === "logic") {
      op = { op: "move", from, to: afterDelete(from, onto), side: right ? "after" : "before" };
    } else {
      const k = onto.lastIndexOf("outs");
      const node = onto.slice(0, k);
      let index = onto[k + 1] + (right ? 1 : 0);
      const fk = from.lastIndexOf("outs");
      const sameNode = fk === k && from.slice(0, fk).every((s, i) => s === node[i]);
      if (sameNode && from[fk + 1] < index) index -= 1;
      op = { op: "move", from, to: afterDelete(from, node), index };
    }
    edit(op).then((ok) => {
      if (!ok) return;
      const e = elements().find((x) => x.dataset.sig === sig);
      if (e) { L.sel = e.dataset.path; mark(); }
    });
  }

  function add(what, shiftKey) {
    if (!L.id) return;
    if (shiftKey && (CONTACTS[what] || COILS[what])) change(what);
    else if (CONTACTS[what]) addContact(what);
    else if (what === "BRANCH") addBranch();
    else if (COILS[what]) addOutput(what, false);
    else if (what === "BOX") addOutput($("draw-box").value, true);
  }

  function remove() {
    if (!L.sel) return;
    const els = elements();
    const k = els.findIndex((e) => e.dataset.path === L.sel);
    edit({ op: "delete", at: JSON.parse(L.sel) }).then((ok) => {
      if (!ok) return;
      const now = elements();
      const e = now[Math.min(Math.max(k - 1, 0), now.length - 1)];
      L.sel = e ? e.dataset.path : null;
      mark();
    });
  }

  // ------------------------------------------------------------- keyboard
  function move(key) {
    const els = elements();
    if (!els.length) return;
    const cur = selected();
    if (!cur) { L.sel = els[0].dataset.path; mark(); return; }
    let next = null;
    if (key === "ArrowLeft" || key === "ArrowRight") {
      const k = els.indexOf(cur) + (key === "ArrowRight" ? 1 : -1);
      next = els[Math.min(Math.max(k, 0), els.length - 1)];
    } else {   // the nearest element above or below
      const r = cur.getBoundingClientRect();
      const down = key === "ArrowDown";
      let best = Infinity;
      for (const e of els) {
        const q = e.getBoundingClientRect();
        const dy = down ? q.top - r.top : r.top - q.top;
        if (dy <= 1) continue;
        const d = dy * dy + (q.left - r.left) * (q.left - r.left);
        if (d < best) { best = d; next = e; }
      }
    }
    if (next) { L.sel = next.dataset.path; mark(); next.scrollIntoView({ block: "nearest" }); }
  }

  function onKey(e) {
    if (e.target !== $("draw-rung")) return;
    const ctrl = e.ctrlKey || e.metaKey;
    if (ctrl && (e.key === "z" || e.key === "Z")) {
      e.preventDefault();
      send(e.shiftKey ? "/ladder/redo" : "/ladder/undo", {});
    } else if (ctrl && (e.key === "y" || e.key === "Y")) {
      e.preventDefault();
      send("/ladder/redo", {});
    } else if (e.altKey && (e.key === "ArrowLeft" || e.key === "ArrowRight")) {
      e.preventDefault();
      shift(e.key === "ArrowRight" ? 1 : -1);
    } else if (ctrl || e.altKey) {
      return;
    } else if (e.key.startsWith("Arrow")) {
      e.preventDefault();
      move(e.key);
    } else if (e.key === "Enter" || e.key === "F2") {
      e.preventDefault();
      editOperands();
    } else if (e.key === "Delete" || e.key === "Backspace") {
      e.preventDefault();
      remove();
    } else if (KEYS[e.key.toLowerCase()]) {
      e.preventDefault();
      add(KEYS[e.key.toLowerCase()], e.shiftKey);
    }
  }

  document.addEventListener("DOMContentLoaded", () => {
    $("draw-toggle").addEventListener("click", async () => {
      const show = $("draw-tools").hidden;
      $("draw-tools").hidden = !show;
      $("draw-toggle").setAttribute("aria-expanded", String(show));
      if (!show) { $("draw").hidden = true; return; }
      await listNetworks();
    });
    $("draw-net").addEventListener("focus", listNetworks);
    $("draw-open").addEventListener("click", async () => { await listNetworks(); await open(); });
    $("draw-new").addEventListener("click", newNetwork);
    $("draw-undo").addEventListener("click", () => send("/ladder/undo", {}));
    $("draw-redo").addEventListener("click", () => send("/ladder/redo", {}));
    for (const b of $("draw-palette").querySelectorAll("button[data-add]")) {
      b.addEventListener("click", (e) => add(b.dataset.add, e.shiftKey));
    }
    const rung = $("draw-rung");
    rung.addEventListener("keydown", onKey);
    rung.addEventListener("click", (e) => {
      const el = e.target.closest(".lad-el");
      if (!el || el.dataset.path === "[\"pending\"]") return;
      L.sel = el.dataset.path;
      mark();
      rung.focus();
    });
    let dragged = null;
    rung.addEventListener("dragstart", (e) => {
      const el = e.target.closest && e.target.closest(".lad-el");
      if (!el || el.dataset.path === "[\"pending\"]") { e.preventDefault(); return; }
      dragged = el;
      e.dataTransfer.effectAllowed = "move";
      e.dataTransfer.setData("text/plain", "");
    });
    rung.addEventListener("dragover", (e) => {
      if (dragged && e.target.closest(".lad-el")) e.preventDefault();
    });
    rung.addEventListener("drop", (e) => {
      const onto = e.target.closest(".lad-el");
      if (!dragged || !onto) return;
      e.preventDefault();
      const r = onto.getBoundingClientRect();
      drop(dragged, onto, e.clientX > r.left + r.width / 2);
      dragged = null;
    });
    rung.addEventListener("dragend", () => { dragged = null; });
    rung.addEventListener("dblclick", (e) => { if (e.target.closest(".lad-el")) editOperands(); });
  });
})();

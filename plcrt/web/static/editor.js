// plcrt panel: the STL editor (docs/panel.md, "Editing the program").
// CodeMirror 6 (static/vendor/codemirror.min.js, the global CM) with an
// S7-200 STL mode, the server's `plcrt check` diagnostics while typing,
// completion of instructions, addresses and symbols, hover help, and
// Download / Save / Reload over the /editor/ endpoints.  Program text is
// only ever shown as text: CodeMirror's document, textContent, never HTML.
"use strict";

(function () {
  const $ = (id) => document.getElementById(id);
  const E = {
    view: null, base: "", stamp: null, seen: null, files: null, insns: new Map(),
    loaded: false, busy: false, checks: 0, lastDiags: [],
  };
  window.plcrtEditor = E;   // for the tests and the curious

  const HEADERS = new Set(["ORGANIZATION_BLOCK", "SUBROUTINE_BLOCK", "INTERRUPT_BLOCK",
    "END_ORGANIZATION_BLOCK", "END_SUBROUTINE_BLOCK", "END_INTERRUPT_BLOCK", "BEGIN",
    "NETWORK", "VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT", "VAR", "END_VAR", "TITLE"]);
  // addresses: bits (I0.0, SM0.1, L1.2), bytes/words/double words (VW100,
  // AIW0, SMB30), timers, counters, accumulators, high-speed counters and
  // pointers (&VB100, *VD4, *AC1)
  const ADDRESS = /^[&*]?(?:(?:SM|[IQMVSL])\d+\.\d+|(?:SM|AI|AQ|[IQMVSL])[BWD]\d+|AC\d|HC\d|[TC]\d+)(?![\w.])/i;
  const NUMBER = /^(?:16#[0-9A-F]+|2#[01]+|[+-]?\d+(?:\.\d+)?(?:E[+-]?\d+)?)(?![\w#])/i;
  const USED = /\b(?:(?:SM|[IQMVS])\d+\.[0-7]|(?:SM|AI|AQ|[IQMVS])[BWD]\d+|[TC]\d+)\b/g;
  const COMMON = ["SM0.0", "SM0.1", "SM0.4", "SM0.5", "SM1.0", "SM1.1"];

  // ------------------------------------------------------------- the mode
  const stl = {
    name: "s7-200-stl",
    startState: () => ({ first: true }),
    token(stream, state) {
      if (stream.sol()) state.first = true;
      if (stream.eatSpace()) return null;
      if (stream.match("//")) { stream.skipToEnd(); return "comment"; }
      if (stream.match(/^"(?:[^"\\]|\\.)*"?/) || stream.match(/^'[^']*'?/)) return "string";
      if (state.first) {
        state.first = false;
        const word = stream.match(/^[^\s,;:=]+=?|^=[A-Z]*/i);
        if (!word) { stream.next(); return null; }
        const w = word[0].replace(/=$/, "").toUpperCase();
        if (w === "TITLE") { stream.skipToEnd(); return "heading"; }
        if (HEADERS.has(w)) return "heading";
        return E.insns.has(word[0].toUpperCase()) ? "keyword" : null;
      }
      if (stream.match(ADDRESS)) return "atom";
      if (stream.match(NUMBER)) return "number";
      if (stream.match(/^#?[\w\u0080-\uffff]+/)) {
        const name = stream.current().replace(/^#/, "");
        return symbols().has(name) || stream.current().startsWith("#") ? "variableName" : null;
      }
      stream.next();
      return null;
    },
  };

  function symbols() {
    const h = window.plcrtPanel && window.plcrtPanel.hello;
    if (!h) return new Map();
    if (E.symHello !== h) {
      E.symHello = h;
      E.symMap = new Map(h.symbols.map((s) => [s.name, s]));
    }
    return E.symMap;
  }

  // ------------------------------------------------------------- server
  async function api(route, body) {
    const opts = { method: body === undefined ? "GET" : "POST", cache: "no-store", headers: {} };
    if (body !== undefined) {
      opts.headers["Content-Type"] = "application/json";
      opts.body = JSON.stringify(body);
    }
    try {
      const r = await fetch(route, opts);
      return await r.json();
    } catch (e) {
      return { ok: false, message: "no answer from the panel server" };
    }
  }
  E.api = api;   // the ladder drawing's requests too (ladder_edit.js)

  function status(text, level) {
    const s = $("editor-status");
    s.textContent = text;
    s.className = level || "";
  }

  // ------------------------------------------------------------- diagnostics
  function toCM(doc, items) {
    const out = [];
    for (const d of items) {
      const n = Math.min(Math.max(d.line || 1, 1), doc.lines);
      const line = doc.line(n);
      let from = line.from + Math.min(Math.max((d.column || 1) - 1, 0), line.length);
      let to = from;
      const rest = doc.sliceString(from, line.to);
      const m = rest.match(/^[^\s,]+/);
      to = m ? from + m[0].length : line.to;
      if (to === from) { from = line.from; to = line.to; }
      out.push({ from, to, severity: d.severity === "note" ? "info" : d.severity,
        message: (d.where ? d.where + ": " : "") + d.message });
    }
    return out;
  }

  function listDiags(items, more) {
    E.lastDiags = items;
    const ul = $("editor-diags");
    ul.replaceChildren();
    for (const d of items) {
      const li = document.createElement("li");
      li.className = d.severity;
      li.textContent = (d.line ? "line " + d.line + ":" + d.column + ": " : "") +
        d.severity + ": " + d.message + (d.where ? " [" + d.where + "]" : "");
      if (d.line) {
        li.tabIndex = 0;
        const go = () => goTo(d.line, d.column);
        li.addEventListener("click", go);
        li.addEventListener("keydown", (e) => { if (e.key === "Enter") go(); });
      }
      ul.append(li);
    }
    if (more) ul.append(Object.assign(document.createElement("li"), { textContent: more }));
    const errors = items.filter((d) => d.severity === "error").length;
    $("editor-count").textContent = errors ? errors + " error(s)" :
      (items.length ? items.length + " warning(s)" : "no errors");
    $("editor-count").className = errors ? "error" : "ok";
  }

  function goTo(line, column) {
    const doc = E.view.state.doc;
    const l = doc.line(Math.min(Math.max(line, 1), doc.lines));
    const pos = l.from + Math.min(Math.max((column || 1) - 1, 0), l.length);
    E.view.dispatch({ selection: { anchor: pos }, scrollIntoView: true });
    E.view.focus();
  }

  async function lint(view) {
    const text = view.state.doc.toString();
    const ans = await api("/editor/check", { text });
    E.checks += 1;
    if (!ans.diagnostics) { status(ans.message || "check failed", "error"); return []; }
    if (view.state.doc.toString() === text) listDiags(ans.diagnostics, ans.more);
    return toCM(view.state.doc, ans.diagnostics);
  }

  // ------------------------------------------------------------- completion
  function complete(ctx) {
    const word = ctx.matchBefore(/[#&*]?[\w.\u0080-\uffff=<>+\-/]*/);
    if (!word || (word.from === word.to && !ctx.explicit)) return null;
    const line = ctx.state.doc.lineAt(ctx.pos);
    const first = !line.text.slice(0, word.from - line.from).trim();
    const options = [];
    if (first) {
      for (const [m, i] of E.insns) {
        options.push({ label: m, type: "keyword", detail: i.summary, info: operandText(i) });
      }
      for (const h of ["NETWORK", "TITLE=", "BEGIN"]) options.push({ label: h, type: "keyword" });
    } else {
      const seen = new Set();
      for (const s of symbols().values()) {
        options.push({ label: s.name, type: "variable", detail: s.address,
          info: s.comment || undefined });
        seen.add(s.address.toUpperCase());
      }
      const h = window.plcrtPanel && window.plcrtPanel.hello;
      const addrs = h ? h.inputs.concat(h.outputs).map((x) => x.addr) : [];
      // and the addresses the text already uses (the first 500)
      const used = ctx.state.doc.toString().match(USED) || [];
      for (const a of addrs.concat(COMMON, used.slice(0, 500))) {
        if (!seen.has(a.toUpperCase())) { seen.add(a.toUpperCase()); options.push({ label: a, type: "constant" }); }
      }
    }
    return { from: word.from, options, validFor: /^[#&*]?[\w.\u0080-\uffff=<>+\-/]*$/ };
  }

  function operandText(i) {
    return i.operands.length ? "operands: " + i.operands.join("; ") : "no operands";
  }

  // ------------------------------------------------------------- hover help
  function hover(view, pos) {
    const line = view.state.doc.lineAt(pos);
    const text = line.text;
    let a = pos - line.from, b = a;
    const part = /[^\s,;]/;
    while (a > 0 && part.test(text[a - 1])) a -= 1;
    while (b < text.length && part.test(text[b])) b += 1;
    if (a === b) return null;
    const word = text.slice(a, b);
    const first = !text.slice(0, a).trim();
    let lines = null;
    const insn = E.insns.get(word.toUpperCase());
    if (first && insn) {
      lines = [insn.m + ": " + insn.summary + " (" + insn.family + ")", operandText(insn)];
    } else {
      const s = symbols().get(word.replace(/^#/, ""));
      if (s) lines = [s.name + " = " + s.address, s.comment || ""];
    }
    if (!lines) return null;
    return {
      pos: line.from + a, end: line.from + b, above: true,
      create() {
        const dom = document.createElement("div");
        dom.className = "stl-help";
        for (const t of lines) if (t) dom.append(Object.assign(document.createElement("div"), { textContent: t }));
        return { dom };
      },
    };
  }

  // ------------------------------------------------------------- the editor
  function build() {
    const theme = CM.HighlightStyle.define([
      { tag: CM.tags.keyword, color: "#0d47a1", fontWeight: "bold" },
      { tag: CM.tags.heading, color: "#6a1b9a", fontWeight: "bold" },
      { tag: CM.tags.atom, color: "#00695c" },
      { tag: CM.tags.number, color: "#e65100" },
      { tag: CM.tags.string, color: "#e65100" },
      { tag: CM.tags.comment, color: "#757575", fontStyle: "italic" },
      { tag: CM.tags.variableName, color: "#ad1457" },
    ]);
    // in a shadow root: CodeMirror's styles go into a constructed style
    // sheet there, which the page's Content-Security-Policy (style-src
    // 'self', no inline style) allows, where a <style> element is refused
    const host = $("editor-host");
    const root = host.shadowRoot || host.attachShadow({ mode: "open" });
    const look = CM.EditorView.theme({
      "&": { height: "340px", border: "1px solid #ccc", fontSize: "13px", background: "#fff" },
      ".cm-scroller": { fontFamily: "monospace" },
      ".stl-help": { padding: "3px 6px", fontSize: "12px", maxWidth: "40em" },
      ".stl-help div:first-child": { fontWeight: "bold" },
    });
    E.view = new CM.EditorView({
      parent: root, root,
      state: CM.EditorState.create({
        doc: "",
        extensions: [
          CM.lineNumbers(), CM.highlightActiveLineGutter(), CM.history(), CM.drawSelection(),
          CM.highlightActiveLine(), CM.highlightSelectionMatches(),
          CM.StreamLanguage.define(stl), CM.syntaxHighlighting(theme), look,
          CM.linter(lint, { delay: 400 }), CM.lintGutter(),
          CM.autocompletion({ override: [complete] }),
          CM.hoverTooltip(hover),
          CM.keymap.of([...CM.completionKeymap, ...CM.defaultKeymap, ...CM.historyKeymap,
            ...CM.searchKeymap, CM.indentWithTab]),
          CM.EditorView.updateListener.of((u) => { if (u.docChanged) dirtyMark(); }),
          CM.EditorView.contentAttributes.of({ "aria-label": "STL program" }),
        ],
      }),
    });
  }

  function dirty() { return E.view !== null && E.view.state.doc.toString() !== E.base; }
  E.dirty = dirty;
  function dirtyMark() { $("editor-name").classList.toggle("dirty", dirty()); }

  function setText(text) {
    E.view.dispatch({ changes: { from: 0, to: E.view.state.doc.length, insert: text } });
  }

  async function loadSource(ask) {
    const ans = await api("/editor/source");
    if (!ans.ok) { status(ans.message || "the program cannot be read", "error"); return false; }
    if (ask && dirty() && !window.confirm(ask)) {
      E.seen = E.stamp = ans.stamp;   // keep the edits; a save replaces the file
      status("kept your edits; Save replaces the file on disk", "warning");
      return false;
    }
    E.base = ans.text.replace(/\r\n?/g, "\n");
    E.stamp = E.seen = ans.stamp;
    E.loaded = true;
    $("editor-name").textContent = ans.name + (ans.writable ? "" : " (read-only)");
    setText(E.base);
    dirtyMark();
    return true;
  }

  async function words() {
    const ans = await api("/editor/words");
    if (ans.ok) for (const i of ans.instructions) E.insns.set(i.m, i);
  }

  async function open() {
    const sec = $("editor");
    const show = sec.hidden;
    sec.hidden = !show;
    $("edit-toggle").setAttribute("aria-expanded", String(show));
    if (!show) return;
    if (!E.view) {
      await words();
      build();
    }
    if (!E.loaded) await loadSource(null);
    E.view.focus();
  }

  async function download() {
    if (E.busy) return;
    E.busy = true;
    status("downloading ...");
    const ans = await api("/editor/download", { text: E.view.state.doc.toString() });
    E.busy = false;
    status(ans.message || "download failed", ans.ok ? "ok" : "error");
    if (ans.diagnostics) {
      listDiags(ans.diagnostics, ans.more);
      E.view.dispatch(CM.setDiagnostics(E.view.state, toCM(E.view.state.doc, ans.diagnostics)));
    }
  }

  async function save() {
    const text = E.view.state.doc.toString();
    const ans = await api("/editor/save", { text, stamp: E.stamp });
    status(ans.message || "save failed", ans.ok ? "ok" : "error");
    if (ans.ok) {
      E.base = text;
      E.stamp = E.seen = ans.stamp;
      dirtyMark();
    }
  }

  // the file changed on disk (another editor, git): load it, asking first
  // when the page holds edits
  async function poll() {
    if (!E.loaded || document.hidden) return;
    const ans = await api("/editor/stamp");
    if (ans.ok && ans.stamp !== E.seen) {
      E.seen = ans.stamp;
      if (await loadSource("The program file changed on disk. Discard your edits and load it?")) {
        status("the file changed on disk: loaded again", "warning");
      }
    }
  }

  // a new hello: another lesson (its own file) or the same program again
  E.onHello = function (h) {
    const files = h.files.join("\n");
    const before = E.files;
    E.files = files;
    $("edit-toggle").hidden = !h.editable;
    // another program (a lesson switched to, asked about before): its file,
    // never the edits of the previous one, which Save would write into it
    if (E.loaded && before !== null && before !== files) loadSource(null);
  };

  document.addEventListener("DOMContentLoaded", () => {
    $("edit-toggle").addEventListener("click", open);
    $("editor-download").addEventListener("click", download);
    $("editor-save").addEventListener("click", save);
    $("editor-reload").addEventListener("click", () =>
      loadSource("Discard your edits and load the file again?"));
    setInterval(poll, 1500);
    window.addEventListener("beforeunload", (e) => { if (dirty()) e.preventDefault(); });
    // the first hello may have come before this script ran
    if (window.plcrtPanel && window.plcrtPanel.hello) E.onHello(window.plcrtPanel.hello);
  });
})();

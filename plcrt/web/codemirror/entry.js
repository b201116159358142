// What the panel's STL editor uses of CodeMirror 6, as one global: CM.
// build.sh bundles this file with esbuild into
// plcrt/web/static/vendor/codemirror.min.js.
export { EditorState, StateEffect, StateField, Compartment } from "@codemirror/state";
export {
  EditorView, keymap, lineNumbers, highlightActiveLine, highlightActiveLineGutter,
  drawSelection, hoverTooltip, ViewPlugin,
} from "@codemirror/view";
export {
  StreamLanguage, syntaxHighlighting, HighlightStyle, defaultHighlightStyle,
  bracketMatching, indentOnInput,
} from "@codemirror/language";
export { tags } from "@lezer/highlight";
export { linter, lintGutter, setDiagnostics, forceLinting } from "@codemirror/lint";
export {
  autocompletion, completionKeymap, closeBrackets,
} from "@codemirror/autocomplete";
export { defaultKeymap, history, historyKeymap, indentWithTab } from "@codemirror/commands";
export { searchKeymap, highlightSelectionMatches } from "@codemirror/search";

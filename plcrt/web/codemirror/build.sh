#!/bin/sh
# Build plcrt/web/static/vendor/codemirror.min.js and its LICENSE from the
# pinned versions of package-lock.json (needs node and npm; run from anywhere).
# The bundle is committed: serving or installing plcrt never runs this.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
out="$here/../static/vendor"
cd "$here"
npm ci --no-audit --no-fund
mkdir -p "$out"
npx esbuild entry.js --bundle --minify --format=iife --global-name=CM \
    --target=es2020 --legal-comments=none --metafile=meta.json \
    --outfile="$out/codemirror.min.js"
# one LICENSE for the bundle: the licence of every package it holds
node -e '
const fs = require("fs"), path = require("path");
const meta = JSON.parse(fs.readFileSync("meta.json", "utf8"));
const pkgs = new Set();
for (const f of Object.keys(meta.inputs)) {
  const m = f.match(/node_modules\/((?:@[^/]+\/)?[^/]+)\//);
  if (m) pkgs.add(m[1]);
}
let text = "codemirror.min.js bundles the following packages (built by plcrt/web/codemirror/build.sh).\n";
for (const p of [...pkgs].sort()) {
  const dir = path.join("node_modules", p);
  const info = JSON.parse(fs.readFileSync(path.join(dir, "package.json"), "utf8"));
  const lic = fs.readdirSync(dir).find(n => /^licen[cs]e/i.test(n));
  text += "\n==== " + p + " " + info.version + " (" + info.license + ")\n\n";
  text += lic ? fs.readFileSync(path.join(dir, lic), "utf8").trim() + "\n" : "(no licence file)\n";
}
fs.writeFileSync(process.argv[1], text);
' "$out/LICENSE"
rm -f meta.json
ls -l "$out"

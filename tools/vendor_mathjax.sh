#!/usr/bin/env bash
# Fetch MathJax from the npm registry and unpack its ES5 bundle into a folder that the
# book copies to its output root (html_extra_path), so math renders without internet.
set -euo pipefail
version="${1:-3.2.2}"
dest="${2:-book/_vendor/mathjax}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
( cd "$tmp" && npm pack "mathjax@${version}" --silent >/dev/null )
tar -xzf "$tmp"/mathjax-*.tgz -C "$tmp"
rm -rf "$dest"
mkdir -p "$dest"
cp -r "$tmp/package/es5/." "$dest/"
test -s "$dest/tex-chtml.js"
echo "MathJax ${version} vendored into ${dest}"

#!/usr/bin/env bash
# Maintainers only (CI never runs it): rebuild ropesim/viewer/assets/three.min.js, the three.js the browser viewer
# inlines into every page, from the npm registry with esbuild, at the versions pinned in
# scripts/three_bundle/package.json and package-lock.json (npm ci checks every package's hash).
#
#     scripts/build_three_bundle.sh          # needs node and npm; about 10 s
#
# To move to another three.js: change its version in package.json, run `npm install --package-lock-only` in
# scripts/three_bundle/, run this, then the browser tests (python -m pytest tests/test_viewer_browser.py).
# The bundle is one IIFE that defines the global THREE with what scripts/three_bundle/entry.js exports; three.js's
# MIT licence is copied beside it (three.LICENSE) and into the bundle's first comment, so every page carries it.
set -euo pipefail
cd "$(dirname "$0")/.."
src=scripts/three_bundle
assets=ropesim/viewer/assets
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$src/package.json" "$src/package-lock.json" "$src/entry.js" "$work/"
(cd "$work" && npm ci --no-audit --no-fund --loglevel=error)
version=$(node -p "require('$work/node_modules/three/package.json').version")
esbuild_version=$(node -p "require('$work/node_modules/esbuild/package.json').version")
licence="$work/node_modules/three/LICENSE"
{
    echo "/*! three.js $version (https://threejs.org), the parts ropesim's viewer uses (scripts/three_bundle/entry.js),"
    echo "    bundled by scripts/build_three_bundle.sh with esbuild $esbuild_version. Its licence:"
    echo
    sed 's/^/    /' "$licence"
    echo "*/"
} > "$work/banner.js"
"$work/node_modules/.bin/esbuild" "$work/entry.js" --bundle --minify --format=iife --global-name=THREE \
    --target=es2020 --legal-comments=none --log-level=warning --outfile="$work/three.min.js"
cat "$work/banner.js" "$work/three.min.js" > "$assets/three.min.js"
cp "$licence" "$assets/three.LICENSE"
if grep -qi "</script" "$assets/three.min.js"; then
    echo "the bundle contains '</script': it cannot be inlined into a page" >&2
    exit 1
fi
echo "$assets/three.min.js: three.js $version, $(wc -c < "$assets/three.min.js") bytes"

#!/usr/bin/env bash
# Maintainers only (CI never runs it): copy into docs/vendor/ what the documentation site serves itself instead of
# fetching from elsewhere when a page is viewed: KaTeX (the equations) and the Roboto and Roboto Mono fonts (the
# text and the code; mkdocs.yml has theme.font: false, so Material asks Google Fonts for nothing). The versions are
# pinned in scripts/docs_assets/package.json and package-lock.json (npm ci checks every package's hash).
#
#     scripts/vendor_docs_assets.sh          # needs npm; a few seconds
#
# To move to another version: change it in package.json, run `npm install --package-lock-only` in
# scripts/docs_assets/, run this, then `mkdocs build --strict` and python -m pytest tests/test_docs.py.
# Only the woff2 files are kept (every browser the site supports reads them), and of the fonts only the Latin,
# Latin Extended and Greek subsets (plus Roboto's math and symbols), in the weights Material uses: 300, 400, 700 and
# their italics for the text, 400, 700 and italics for the code. Each package's licence is copied beside it.
set -euo pipefail
cd "$(dirname "$0")/.."
src=scripts/docs_assets
out=docs/vendor
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$src/package.json" "$src/package-lock.json" "$work/"
(cd "$work" && npm ci --no-audit --no-fund --loglevel=error)
modules="$work/node_modules"
rm -rf "$out/katex" "$out/fonts"
mkdir -p "$out/katex/fonts" "$out/katex/contrib" "$out/fonts"

katex="$modules/katex"
cp "$katex/dist/katex.min.js" "$katex/dist/katex.min.css" "$katex/LICENSE" "$out/katex/"
cp "$katex/dist/contrib/auto-render.min.js" "$out/katex/contrib/"
cp "$katex/dist/fonts/"*.woff2 "$out/katex/fonts/"
# keep only the woff2 source of each @font-face: the woff and ttf files are not shipped
python3 - "$out/katex/katex.min.css" <<'EOF'
import re, sys
path = sys.argv[1]
css = open(path, encoding="utf-8").read()
css, n = re.subn(r'(url\(fonts/[\w-]+\.woff2\) format\("woff2"\)),url\([^)]*\.woff\) format\("woff"\),url\([^)]*\.ttf\) format\("truetype"\)',
                 r"\1", css)
assert n >= 20 and ".woff)" not in css and ".ttf)" not in css, f"KaTeX's CSS changed its @font-face form ({n} replaced)"
open(path, "w", encoding="utf-8").write(css)
EOF

python3 - "$modules/@fontsource" "$out/fonts" <<'EOF'
"""fonts.css: the @font-face rules of the kept subsets and weights, pointing at the woff2 files copied beside it."""
import re, shutil, sys
from pathlib import Path

modules, out = Path(sys.argv[1]), Path(sys.argv[2])
FONTS = {"roboto": (("300", "400", "700"), ("latin", "latin-ext", "greek", "math", "symbols")),
         "roboto-mono": (("400", "700"), ("latin", "latin-ext", "greek"))}
rules = []
for name, (weights, subsets) in FONTS.items():
    package = modules / name
    for weight in weights:
        for style in ("", "-italic"):
            css = (package / f"{weight}{style}.css").read_text(encoding="utf-8")
            for comment, rule in re.findall(r"/\* ([\w-]+) \*/\s*(@font-face \{.*?\})", css, flags=re.S):
                subset = comment[len(name) + 1:].rsplit("-", 2)[0]
                if subset not in subsets:
                    continue
                woff2 = re.search(r"url\(\./files/([\w-]+\.woff2)\)", rule).group(1)
                shutil.copy(package / "files" / woff2, out / woff2)
                rule = re.sub(r"src: [^;]*;", f"src: url({woff2}) format('woff2');", rule)
                rules.append(f"/* {comment} */\n{rule}\n")
    shutil.copy(package / "LICENSE", out / f"{name}.LICENSE")
header = ("/* Roboto and Roboto Mono (SIL Open Font License 1.1: roboto.LICENSE, roboto-mono.LICENSE), from the\n"
          "   @fontsource packages, copied by scripts/vendor_docs_assets.sh: the site serves its own fonts. */\n\n")
footer = ':root {\n  --md-text-font: "Roboto";\n  --md-code-font: "Roboto Mono";\n}\n'
(out / "fonts.css").write_text(header + "\n".join(rules) + "\n" + footer, encoding="utf-8")
print(f"{out}/fonts.css: {len(rules)} faces")
EOF
echo "$out/katex: KaTeX $(node -p "require('$katex/package.json').version"), $(du -sh "$out/katex" | cut -f1);" \
     "$out/fonts: $(du -sh "$out/fonts" | cut -f1)"

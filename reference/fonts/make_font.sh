#!/usr/bin/env bash
# Makes DejaVuSans-subset.ttf, the font lodeval draws PNG labels with (src/io/label.rs embeds it):
# DejaVu Sans 2.37 (Debian's fonts-dejavu-core) cut to Latin-1, Greek and the few symbols labels use
# (– — ‘ ’ “ ” … − ≈ ≤ ≥ ← →), without hinting or layout tables, so that the binary carries 20 KB
# instead of 760 KB. Needs fonttools (pip install fonttools). Licence: LICENSE-DejaVu.txt.
set -euo pipefail
cd "$(dirname "$0")"
pyftsubset "${1:-/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf}" \
  --unicodes="U+0020-007E,U+00A0-00FF,U+0394,U+03B1-03C9,U+2013,U+2014,U+2018-201D,U+2026,U+2212,U+2248,U+2264,U+2265,U+2192,U+2190" \
  --output-file=DejaVuSans-subset.ttf --layout-features='' --no-hinting

#!/usr/bin/env bash
# Regenerates assets/fonts/DejaVuSans-subset.ttf, the font the figures embed (feature
# `plot`): DejaVu Sans cut to the characters figure labels use, so that the crate carries
# ~51 kB instead of 760 kB and a fresh machine needs no system font.
# Needs Debian's fonts-dejavu-core and fonttools (`pip install fonttools`); not run by CI.
set -euo pipefail
cd "$(dirname "$0")/.."
src=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
# ASCII, Latin-1 (° · × µ ² ³ ¹), Greek, dashes and ellipsis, super- and subscripts,
# ‖, ℓ, arrows, ∂ ∆ ∑ − √ ∞ ≈ ≠ ≤ ≥, ⟨ ⟩.
ranges="U+0020-007E,U+00A0-00FF,U+0391-03C9,U+2013-2014,U+2016,U+2026,U+2070-209C,U+2113,\
U+2190-2193,U+2202,U+2206,U+2211,U+2212,U+221A,U+221E,U+2248,U+2260,U+2264-2265,U+27E8-27E9"
pyftsubset "$src" --unicodes="$ranges" --layout-features='kern' \
  --output-file=assets/fonts/DejaVuSans-subset.ttf
cp /usr/share/doc/fonts-dejavu-core/copyright assets/fonts/LICENSE-DejaVu.txt
ls -l assets/fonts

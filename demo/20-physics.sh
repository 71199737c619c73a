#!/usr/bin/env bash
# The spring world: the standard orb web (silk: EA 0.07 N, 2% pre-strain) is
# far too stiff for explicit steps at useful sizes. Symplectic Euler at 1 ms
# blows up, and the run is refused with the step and particle named; implicit
# Euler (Baraff & Witkin) settles it at 1/60 s in a few steps. The settled web
# is drawn coloured by tension: the rings pull the radii outward, so the radii
# carry most near the frame.
set -eu
: "${SPN:?}" "${OUT:?}"
"$SPN" export scene:orb -o "$OUT/physics-orb.json"
if "$SPN" settle "$OUT/physics-orb.json" -o "$OUT/physics-orb-explicit.json" --solver symplectic --dt 1e-3 \
    2> "$OUT/physics-explicit-blowup.txt"; then
    echo "physics demo: symplectic Euler at 1 ms was expected to blow up" >&2
    exit 1
fi
cat "$OUT/physics-explicit-blowup.txt"
"$SPN" settle "$OUT/physics-orb.json" -o "$OUT/physics-orb-settled.json" --solver implicit --dt 0.0166667 \
    --tol 1e-9 2>&1 | tee "$OUT/physics-implicit-settle.txt"
if "$SPN" render --help >/dev/null 2>&1; then
    "$SPN" render "$OUT/physics-orb-settled.json" -o "$OUT/physics-tension.png" --colour-by tension ||
        echo "physics demo: render failed, picture skipped"
fi

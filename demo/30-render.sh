#!/usr/bin/env bash
# Rendering and export showcase (issue 3): a web over a procedural sky-and-
# branches backdrop, the thesis' grey shades with and without alpha (Mehla
# 2005, figs. 5.40-5.43), a dew-covered web, a tension-coloured web, a
# perspective view coloured by thread kind, and the same web exported to OBJ,
# PLY and a POV-Ray scene (rendered when povray is installed).
# Env: SPN = the spinneret program, OUT = the output folder.
set -eu
: "${SPN:?}" "${OUT:?}"
BIN=$(dirname "$SPN")
P="$OUT/30-render"

# The backdrop and the web come from two small programs in examples/.
"$BIN/example_sky_backdrop" "$P-backdrop.png" 1600x1200 7
"$BIN/example_loaded_web" "$P-web.json"
WEB="$P-web.json"
BG=(--background "$P-backdrop.png")

# The hero: thesis shade and alpha, with silk sheen and a soft glow.
"$SPN" render "$WEB" -o "$P-hero.png" "${BG[@]}" --shade 0.86,0.88,0.87 --alpha 0.75 --sheen 1 --glow 0.5

# Figs. 5.40-5.43: two grey shades, each without and with alpha 0.7.
"$SPN" render "$WEB" -o "$P-shade-light.png" "${BG[@]}" --shade 0.86,0.88,0.87
"$SPN" render "$WEB" -o "$P-shade-light-alpha.png" "${BG[@]}" --shade 0.86,0.88,0.87 --alpha 0.7
"$SPN" render "$WEB" -o "$P-shade-dark.png" "${BG[@]}" --shade 0.69,0.71,0.73
"$SPN" render "$WEB" -o "$P-shade-dark-alpha.png" "${BG[@]}" --shade 0.69,0.71,0.73 --alpha 0.7

# Dew: the thesis' future work, drops on the capture spiral.
"$SPN" render "$WEB" -o "$P-dew.png" "${BG[@]}" --shade 0.86,0.88,0.87 --alpha 0.6 --dew \
    --dew-radius 0.0016 --dew-spacing 0.0075 --sheen 0.6 --glow 0.3

# Physics made visible: tension per spring, and the kinds in perspective.
"$SPN" render "$WEB" -o "$P-tension.png" --colour-by tension --width-scale 1.6 --glow 0.3
"$SPN" render "$WEB" -o "$P-kinds-persp.png" --colour-by kind --camera persp --yaw 35 --pitch 20 --width-scale 1.4
"$SPN" render "$WEB" -o "$P-dew.svg" --dew --background-color 0.05,0.07,0.1

# A turntable: the frame sequence writer, through ffmpeg when it is installed.
if command -v ffmpeg >/dev/null 2>&1; then
    "$SPN" render "$WEB" -o "$P-turntable.gif" --turntable 48 --fps 16 --size 480x480 "${BG[@]}" \
        --shade 0.86,0.88,0.87 --alpha 0.75 --sheen 1 --glow 0.4 --quiet
else
    echo "ffmpeg not installed: skipped the turntable"
fi

# Exports: polylines for Blender/Houdini, tubes for Maya, a POV-Ray scene.
"$SPN" export "$WEB" -o "$P.obj"
"$SPN" export "$WEB" -o "$P-tubes.ply" --tubes 0.0004 --sides 6
"$SPN" export "$WEB" -o "$P.pov" "${BG[@]}" --shade 0.86,0.88,0.87 --dew --dew-radius 0.0016 --dew-spacing 0.0075
if command -v povray >/dev/null 2>&1; then
    (cd "$OUT" && povray +W800 +H800 +A0.1 -D +O30-render-povray.png 30-render.pov >30-render-povray.log 2>&1) ||
        echo "povray failed: see $OUT/30-render-povray.log"
else
    echo "povray not installed: skipped rendering $P.pov"
fi
echo "render: pictures in $OUT/30-render-*"

#!/usr/bin/env bash
# spinneret render and export from the command line: ink of a hand-made plus
# sign (tests/data/render/cross.json) where the strokes are and nowhere else,
# alpha 0.7 over white, a background image showing through, the same pixels
# twice, every exporter's file, and bad options refused with exit 2 and no file.
. "$(dirname "$0")/lib/common.sh" "$@"
CROSS=$DATA/render/cross.json

# A PNG reader and writer small enough to trust (zlib + the five row filters).
cat >"$T/png.py" <<'PY'
import struct, sys, zlib
def read(path):
    data = open(path, 'rb').read()
    assert data[:8] == b'\x89PNG\r\n\x1a\n'
    pos, idat, w = 8, b'', 0
    while pos < len(data):
        n, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b'IHDR':
            w, h, depth, ctype = struct.unpack('>IIBB', body[:10])
            assert depth == 8 and ctype in (2, 6)
            ch = 4 if ctype == 6 else 3
        elif kind == b'IDAT':
            idat += body
        pos += 12 + n
    raw, stride, rows, prev = zlib.decompress(idat), w * ch, [], bytearray(w * ch)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - ch] if i >= ch else 0
            b, c = prev[i], prev[i - ch] if i >= ch else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * ch:x * ch + 3]) for x in range(w)])
        prev = line
    return rows
def write(path, w, h, colour_at):
    raw = b''.join(b'\0' + bytes(v for x in range(w) for v in colour_at(x, y)) for y in range(h))
    chunk = lambda k, b: struct.pack('>I', len(b)) + k + b + struct.pack('>I', zlib.crc32(k + b))
    open(path, 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0))
                           + chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b''))
PY

# 1. Ink where expected: --margin 0.1 on 200 px frames the 0.8 m cross at
# 200 px/m around the centre; lines 1.3 * 20 * 200/1200 = 4.33 px wide.
"$SPN" render "$CROSS" -o "$T/cross.png" --size 200x200 --margin 0.1 --width-scale 20 --shade 1,1,1 2>"$T/err" ||
    fail "render exited $?: $(cat "$T/err")"
python3 - "$T" <<'PY' || fail "ink of the cross"
import math, sys; sys.path.insert(0, sys.argv[1]); import png
px = png.read(sys.argv[1] + '/cross.png')
assert len(px) == 200 and len(px[0]) == 200
half = 1.3 * 20 * 200 / 1200 / 2
def dist(x, y):   # to the two segments, pixel centres
    cx, cy = x + 0.5, y + 0.5
    dh = math.hypot(max(20 - cx, 0, cx - 180), cy - 100)
    dv = math.hypot(cx - 100, max(20 - cy, 0, cy - 180))
    return min(dh, dv)
ink = stray = 0; weak = []
for y in range(200):
    for x in range(200):
        v, d = px[y][x][0], dist(x, y)
        ink += v / 255
        if d > half + 1: stray += v
        if d < half - 1 and v < 254: weak.append((x, y, v))
expected = 2 * 160 * 2 * half - (2 * half) ** 2 + 2 * math.pi * half * half  # two strokes, overlap once, caps
assert stray == 0, stray
assert not weak, weak[:5]
assert abs(ink - expected) < 0.03 * expected, (ink, expected)
PY

# 2. Alpha 0.7 over white: 0.7 * shade + 0.3 * 255, within 2 levels, also at the crossing of two strands.
"$SPN" render "$CROSS" -o "$T/alpha.png" --size 200x200 --margin 0.1 --width-scale 40 \
    --background-color 1,1,1 --shade 0.2,0.4,0.6 --alpha 0.7 || fail "alpha render"
python3 - "$T" <<'PY' || fail "alpha blend"
import sys; sys.path.insert(0, sys.argv[1]); import png
px = png.read(sys.argv[1] + '/alpha.png')
want = [255 * (0.7 * s + 0.3) for s in (0.2, 0.4, 0.6)]
assert all(abs(a - b) <= 2 for a, b in zip(px[100][50], want)), (px[100][50], want)
over = [255 * (0.7 * s + 0.3 * (0.7 * s + 0.3)) for s in (0.2, 0.4, 0.6)]   # two strands cross: twice
assert all(abs(a - b) <= 2 for a, b in zip(px[100][100], over)), (px[100][100], over)
assert px[10][10] == (255, 255, 255)
PY

# 3. Background image: a 2:1 image of four colours covers the square canvas.
python3 - "$T" <<'PY'
import sys; sys.path.insert(0, sys.argv[1]); import png
q = [(255, 0, 0), (0, 255, 0), (0, 0, 255), (255, 255, 0)]
png.write(sys.argv[1] + '/bg.png', 80, 40, lambda x, y: q[(x >= 40) + 2 * (y >= 20)])
PY
"$SPN" render "$CROSS" -o "$T/bg_out.png" --size 200x200 --background "$T/bg.png" || fail "background render"
python3 - "$T" <<'PY' || fail "background shows where no thread is"
import sys; sys.path.insert(0, sys.argv[1]); import png
px = png.read(sys.argv[1] + '/bg_out.png')
assert px[40][40] == (255, 0, 0) and px[40][160] == (0, 255, 0), (px[40][40], px[40][160])
assert px[160][40] == (0, 0, 255) and px[160][160] == (255, 255, 0), (px[160][40], px[160][160])
PY

# 4. Deterministic: the same file and options, the same bytes.
"$SPN" render scene:orb:6x9 -o "$T/d1.png" --size 300x300 --dew --glow 0.5 --colour-by tension || fail "render d1"
"$SPN" render scene:orb:6x9 -o "$T/d2.png" --size 300x300 --dew --glow 0.5 --colour-by tension || fail "render d2"
cmp -s "$T/d1.png" "$T/d2.png" || fail "two renders differ"
for ext in svg pdf; do
    "$SPN" render "$CROSS" -o "$T/v.$ext" --camera persp || fail "render .$ext"
    [ -s "$T/v.$ext" ] || fail "empty .$ext"
done

# 5. Exports: OBJ vertices are the particles, PLY edges the springs, POV scenes per frame.
"$SPN" export "$CROSS" -o "$T/c.obj" || fail "export obj"
[ "$(grep -c '^v ' "$T/c.obj")" = 4 ] || fail "obj vertices"
grep -q '^v -0.4 0 0$' "$T/c.obj" || fail "obj first vertex"
"$SPN" export "$CROSS" -o "$T/c.ply" --tubes 0.01 --sides 5 || fail "export ply"
grep -q '^element vertex 20$' "$T/c.ply" || fail "ply tube vertices"
"$SPN" export "$CROSS" "$CROSS" --frames "$T/frames" --dew --quiet || fail "export frames"
[ -s "$T/frames/frame_00000.pov" ] && [ -s "$T/frames/frame_00001.pov" ] || fail "pov frames"
"$SPN" export "$CROSS" -o "$T/c.json" && "$SPN" info "$T/c.json" | grep -q 'springs: 2' || fail "export json"

# 6. Turntables: a PNG folder always; a GIF through ffmpeg; without ffmpeg a
# clear failure that names the PNG-folder fallback, and no file.
"$SPN" render "$CROSS" -o "$T/spin" --turntable 3 --size 64x48 --quiet || fail "turntable to a folder"
[ -s "$T/spin/frame_00000.png" ] && [ -s "$T/spin/frame_00002.png" ] && [ ! -e "$T/spin/frame_00003.png" ] ||
    fail "turntable frames"
if command -v ffmpeg >/dev/null 2>&1; then
    "$SPN" render "$CROSS" -o "$T/spin.gif" --turntable 4 --size 64x48 --quiet || fail "turntable gif"
    [ "$(head -c 6 "$T/spin.gif")" = GIF89a ] || fail "turntable gif header"
else
    echo "ffmpeg not installed: skipped the GIF turntable"
fi
# Frames are drawn on as many threads as OpenMP would use, and added in
# order: one thread and two give the same files, byte for byte.
OMP_NUM_THREADS=1 "$SPN" render scene:orb:8x12 -o "$T/tt1" --turntable 9 --size 96x80 --dew --quiet ||
    fail "turntable on one thread"
OMP_NUM_THREADS=2 "$SPN" render scene:orb:8x12 -o "$T/tt2" --turntable 9 --size 96x80 --dew --quiet ||
    fail "turntable on two threads"
[ "$(ls "$T/tt2" | wc -l)" -eq 9 ] && diff -r "$T/tt1" "$T/tt2" >/dev/null ||
    fail "turntable frames differ between one and two threads"
# A frame that cannot be written (its name taken by a folder) stops the run
# there: the frames before it stay, none after it is written, the message
# names the file, and no temporary is left.
mkdir -p "$T/ttbad/frame_00004.png"
OMP_NUM_THREADS=2 "$SPN" render scene:orb:8x12 -o "$T/ttbad" --turntable 9 --size 96x80 --quiet 2>"$T/err"
[ $? -eq 1 ] || fail "turntable with an unwritable frame should exit 1"
grep -q 'frame_00004.png' "$T/err" || fail "turntable write error does not name the frame: $(cat "$T/err")"
[ "$(ls "$T/ttbad" | tr '\n' ' ')" = "frame_00000.png frame_00001.png frame_00002.png frame_00003.png frame_00004.png " ] ||
    fail "turntable after a failed frame holds: $(ls "$T/ttbad")"
! ls -a "$T/ttbad" | grep -q tmp || fail "turntable left a temporary: $(ls -a "$T/ttbad")"
SPN_FFMPEG=/nonexistent/ffmpeg "$SPN" render "$CROSS" -o "$T/spin.mp4" --turntable 2 --quiet 2>"$T/err"
[ $? -eq 1 ] || fail "turntable without ffmpeg should exit 1"
grep -q 'ffmpeg' "$T/err" && grep -q 'PNG' "$T/err" || fail "turntable without ffmpeg: $(cat "$T/err")"
[ ! -e "$T/spin.mp4" ] || fail "turntable without ffmpeg left a file"

# 7. Bad options: one message, exit 2, no file.
bad() {
    local out=$1; shift
    "$SPN" "$@" 2>"$T/err"
    local code=$?
    [ $code -eq 2 ] || fail "'$*' exited $code, expected 2"
    [ ! -e "$out" ] || fail "'$*' left $out"
    grep -q "^spinneret " "$T/err" || fail "'$*' gave no message"
}
bad "$T/x.bmp" render "$CROSS" -o "$T/x.bmp"
bad "$T/x.png" render "$CROSS" -o "$T/x.png" --background "$T/none.png"
echo "not a png" >"$T/fake.png"
bad "$T/x.png" render "$CROSS" -o "$T/x.png" --background "$T/fake.png"
bad "$T/x.png" render "$CROSS" -o "$T/x.png" --size 0x0
bad "$T/x.png" render "$CROSS" -o "$T/x.png" --size 100000x100000
bad "$T/x.png" render "$CROSS" -o "$T/x.png" --shade nan,0.5,0.5
bad "$T/x.png" render "$CROSS" -o "$T/x.png" --background-color 0.5,NaN,0.5
bad "$T/x.png" render "$CROSS" -o "$T/x.png" --alpha 1.5
bad "$T/x.png" render "$CROSS" -o "$T/x.png" --colour-by beauty
bad "$T/x.mov" render "$CROSS" -o "$T/x.mov" --turntable 3
bad "$T/x.stl" export "$CROSS" -o "$T/x.stl"
bad "$T/x.obj" export "$CROSS" -o "$T/x.obj" --sides 2
"$SPN" render "$T/missing.json" -o "$T/x.png" 2>/dev/null; [ $? -eq 1 ] || fail "missing input should exit 1"
[ ! -e "$T/x.png" ] || fail "missing input left a file"
echo "render cli ok"

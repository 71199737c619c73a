#!/usr/bin/env python3
"""Make the small models and POV-Ray scenes shipped in assets/ (deterministic).

    scripts/make-models.py [REPO_ROOT]

Models (OBJ, metres, y up, resting above a ground at y = 0):
  sphere.obj  icosphere (2 subdivisions, 162 vertices), radius 0.2, centre (0, 0.8, 0)
  cloth.obj   1 m square, 21 x 21 vertices, at y = 1.2, groups 'corners2' and 'corners4'
  torus.obj   major radius 0.3, minor 0.1, 24 x 12, centre (0, 0.8, 0), lying flat
  table.obj   top 1.2 x 0.8 x 0.05 at height 0.75, four legs (closed boxes)
Scenes (POV-Ray 3.7, mesh2 objects marked for `spinneret film`):
  cloth_table.pov, ball_floor.pov, cloth_pinned2.pov, cloth_pinned4.pov
"""
import math
import os
import sys

ROOT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")


def icosphere(radius, centre, subdivisions):
    t = (1 + 5 ** 0.5) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
             (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(c / math.sqrt(sum(x * x for x in v)) for c in v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache, out = {}, []

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = [(verts[a][k] + verts[b][k]) / 2 for k in range(3)]
                n = math.sqrt(sum(x * x for x in m))
                verts.append(tuple(x / n for x in m))
                cache[key] = len(verts) - 1
            return cache[key]
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            out += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = out
    verts = [tuple(centre[k] + radius * v[k] for k in range(3)) for v in verts]
    return verts, faces


def grid(n, size, y, centre=(0.0, 0.0), turn=0.0):
    """n x n vertices in the x-z plane, turned by `turn` degrees about y; diagonals
    alternate so the cloth has no bias."""
    c, s = math.cos(math.radians(turn)), math.sin(math.radians(turn))
    verts = []
    for j in range(n):
        for i in range(n):
            u, v = -size / 2 + size * i / (n - 1), -size / 2 + size * j / (n - 1)
            verts.append((centre[0] + c * u - s * v, y, centre[1] + s * u + c * v))
    faces = []
    for j in range(n - 1):
        for i in range(n - 1):
            a, b, c, d = j * n + i, j * n + i + 1, (j + 1) * n + i, (j + 1) * n + i + 1
            faces += [(a, c, d), (a, d, b)] if (i + j) % 2 == 0 else [(a, c, b), (b, c, d)]
    return verts, faces


def torus(R, r, nu, nv, centre):
    verts = []
    for i in range(nu):
        u = 2 * math.pi * i / nu
        for j in range(nv):
            v = 2 * math.pi * j / nv
            verts.append((centre[0] + (R + r * math.cos(v)) * math.cos(u), centre[1] + r * math.sin(v),
                          centre[2] + (R + r * math.cos(v)) * math.sin(u)))
    faces = []
    for i in range(nu):
        for j in range(nv):
            a, b = i * nv + j, ((i + 1) % nu) * nv + j
            c, d = i * nv + (j + 1) % nv, ((i + 1) % nu) * nv + (j + 1) % nv
            faces += [(a, c, b), (b, c, d)]
    return verts, faces


def box(lo, hi, base):
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    verts = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
             (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
    faces = []
    for a, b, c, d in quads:
        faces += [(base + a, base + b, base + c), (base + a, base + c, base + d)]
    return verts, faces


def table():
    verts, faces = box((-0.6, 0.70, -0.4), (0.6, 0.75, 0.4), 0)
    for sx in (-1, 1):
        for sz in (-1, 1):
            x, z = sx * 0.52, sz * 0.32
            v, f = box((x - 0.03, 0.0, z - 0.03), (x + 0.03, 0.70, z + 0.03), len(verts))
            verts += v
            faces += f
    return verts, faces


def fmt(x):
    s = "%.6f" % x
    s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def write_obj(path, verts, faces, groups=None):
    with open(path, "w") as fp:
        fp.write("# made by scripts/make-models.py\n")
        for v in verts:
            fp.write("v %s %s %s\n" % tuple(fmt(c) for c in v))
        for name, fs in (groups or [("", faces)]):
            if name:
                fp.write("g %s\n" % name)
            for f in fs:
                fp.write("f %d %d %d\n" % tuple(i + 1 for i in f))


def mesh2(name, verts, faces, marks, texture):
    out = ["#declare %s = mesh2 {" % name]
    out += ["  #local spring_system_%s = %s;" % (k, v) for k, v in marks]
    out.append("  vertex_vectors {")
    out.append("    %d," % len(verts))
    out += ["    <%s, %s, %s>%s" % (fmt(v[0]), fmt(v[1]), fmt(v[2]), "," if i + 1 < len(verts) else "")
            for i, v in enumerate(verts)]
    out.append("  }")
    out.append("  face_indices {")
    out.append("    %d," % len(faces))
    out += ["    <%d, %d, %d>%s" % (f[0], f[1], f[2], "," if i + 1 < len(faces) else "")
            for i, f in enumerate(faces)]
    out.append("  }")
    out.append("  %s" % texture)
    out.append("}")
    out.append("object { %s }" % name)
    return "\n".join(out) + "\n\n"


HEADER = """// %s: made by scripts/make-models.py for `spinneret film`.
// Simulated objects are mesh2 with #local spring_system_* declarations.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <%s> look_at <%s> angle 45 }
light_source { <2, 4, -3> color rgb 1.0 }
light_source { <-3, 3, -1> color rgb 0.4 shadowless }
background { color rgb <0.75, 0.82, 0.9> }

"""

FIXED = [("fixed", "true")]


def free(ks, kb, ds, db, mass, vicinity, extra=()):
    return [("ks", ks), ("kb", kb), ("ds", ds), ("db", db), ("mass", mass), ("vicinity", vicinity)] + \
        list(extra) + [("fixed", "false")]


FLOOR_TEX = "texture { pigment { checker color rgb 0.9 color rgb 0.55 scale 0.25 } finish { diffuse 0.8 } }"
CLOTH_TEX = "texture { pigment { checker color rgb <0.8, 0.1, 0.1> color rgb <0.95, 0.9, 0.8> scale 0.1 } " \
            "finish { diffuse 0.8 } }"


def floor(size):
    h = size / 2
    return [(-h, 0, -h), (h, 0, -h), (h, 0, h), (-h, 0, h)], [(0, 2, 1), (0, 3, 2)]


def scenes(d):
    cloth_v, cloth_f = grid(21, 1.2, 1.0, (0.15, 0.05), 30)
    tv, tf = table()
    fv, ff = floor(6)
    with open(os.path.join(d, "cloth_table.pov"), "w") as fp:
        fp.write(HEADER % ("cloth_table", "1.6, 1.9, -2.2", "0, 0.6, 0"))
        fp.write(mesh2("Floor", fv, ff, FIXED, FLOOR_TEX))
        fp.write(mesh2("Table", tv, tf, FIXED,
                       "texture { pigment { color rgb <0.55, 0.35, 0.2> } finish { diffuse 0.8 } }"))
        fp.write(mesh2("Cloth", cloth_v, cloth_f, free(600, 60, 0.1, 0.02, 0.3, 0), CLOTH_TEX))
    sv, sf = icosphere(0.2, (0, 0.9, 0), 2)
    with open(os.path.join(d, "ball_floor.pov"), "w") as fp:
        fp.write(HEADER % ("ball_floor", "0, 0.7, -2.6", "0, 0.45, 0"))
        fp.write(mesh2("Floor", fv, ff, FIXED, FLOOR_TEX))
        fp.write(mesh2("Ball", sv, sf, free(400, 400, 0.2, 0.2, 1, 0.2),
                       "texture { pigment { color rgb <0.2, 0.4, 0.9> } finish { phong 0.6 } }"))
    n = 21
    for pins, name in (([0, n - 1], "cloth_pinned2.pov"), ([0, n - 1, n * (n - 1), n * n - 1], "cloth_pinned4.pov")):
        cv, cf = grid(n, 1.0, 1.4)
        arr = "array[%d] {%s}" % (len(pins), ", ".join(str(p) for p in pins))
        with open(os.path.join(d, name), "w") as fp:
            fp.write(HEADER % (name[:-4], "0, 2.4, -2.3", "0, 1.0, 0"))
            fp.write(mesh2("Floor", fv, ff, FIXED, FLOOR_TEX))
            fp.write(mesh2("Cloth", cv, cf, free(600, 60, 0.1, 0.02, 0.3, 0, [("fixed_vertices", arr)]), CLOTH_TEX))


def main():
    models = os.path.join(ROOT, "assets", "models")
    os.makedirs(models, exist_ok=True)
    write_obj(os.path.join(models, "sphere.obj"), *icosphere(0.2, (0, 0.8, 0), 2))
    cv, cf = grid(21, 1.0, 1.2)
    n = 21
    corner = lambda v: [f for f in cf if v in f][:1]
    c2 = corner(0) + corner(n - 1)
    c4 = c2 + corner(n * (n - 1)) + corner(n * n - 1)
    rest = [f for f in cf if f not in c4]
    groups = [("cloth", rest), ("corners2", c2), ("corners4", [f for f in c4 if f not in c2])]
    write_obj(os.path.join(models, "cloth.obj"), cv, cf, groups)
    write_obj(os.path.join(models, "torus.obj"), *torus(0.3, 0.1, 24, 12, (0, 0.8, 0)))
    write_obj(os.path.join(models, "table.obj"), *table())
    sc = os.path.join(ROOT, "assets", "scenes")
    os.makedirs(sc, exist_ok=True)
    scenes(sc)


if __name__ == "__main__":
    main()

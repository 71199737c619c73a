/* Exporters round-trip: OBJ and PLY read back by the small readers below give
 * the particles' positions, one polyline per strand and one edge per spring
 * with its kind; tubes put a ring of `sides` vertices at the tube radius
 * around every point; the POV scene renders in povray (when installed)
 * without warnings to a picture with the web in it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <spinneret/spinneret.h>

#if defined(__has_include)
#if __has_include(<assimp/cimport.h>)
#include <assimp/cimport.h>
#include <assimp/scene.h>
#define HAVE_ASSIMP 1
#endif
#endif

/* ---- a small OBJ reader ---------------------------------------------- */

typedef struct obj_data {
    double *v;
    int nv;
    int lines, faces, objects;
    int line_points;     /* sum of indices over `l` elements */
    int max_index;
} obj_data;

static void read_obj(const char *text, obj_data *o)
{
    memset(o, 0, sizeof *o);
    o->v = malloc(strlen(text) * sizeof *o->v); /* generous: fewer numbers than bytes */
    for (const char *p = text; *p;) {
        const char *end = strchr(p, '\n');
        size_t n = end ? (size_t)(end - p) : strlen(p);
        char line[4096];
        snprintf(line, sizeof line, "%.*s", (int)(n < sizeof line ? n : sizeof line - 1), p);
        if (line[0] == 'v' && line[1] == ' ') {
            double *v = o->v + 3 * o->nv++;
            assert_int_equal(sscanf(line + 2, "%lf %lf %lf", v, v + 1, v + 2), 3);
        } else if ((line[0] == 'l' || line[0] == 'f') && line[1] == ' ') {
            if (line[0] == 'l') o->lines++;
            else o->faces++;
            char *q = line + 1;
            long idx;
            char *after;
            while ((idx = strtol(q, &after, 10)), after != q) {
                assert_true(idx >= 1);
                if (idx > o->max_index) o->max_index = (int)idx;
                if (line[0] == 'l') o->line_points++;
                q = after;
            }
        } else if (line[0] == 'o' && line[1] == ' ') {
            o->objects++;
        }
        p += n + (end ? 1 : 0);
    }
}

/* ---- a small ASCII PLY reader ----------------------------------------- */

typedef struct ply_data {
    int nv, nf, ne;
    double *v;
    int (*edge)[3];     /* vertex1, vertex2, kind */
    int *face_size;
} ply_data;

static void read_ply(const char *text, ply_data *d)
{
    memset(d, 0, sizeof *d);
    const char *p = text;
    assert_memory_equal(p, "ply\nformat ascii 1.0\n", 21);
    char word[64];
    int n;
    while (sscanf(p, "%63s", word) == 1 && strcmp(word, "end_header") != 0) {
        if (sscanf(p, "element vertex %d", &n) == 1) d->nv = n;
        if (sscanf(p, "element face %d", &n) == 1) d->nf = n;
        if (sscanf(p, "element edge %d", &n) == 1) d->ne = n;
        p = strchr(p, '\n') + 1;
    }
    p = strchr(p, '\n') + 1;
    d->v = malloc((size_t)(d->nv + 1) * 3 * sizeof *d->v);
    d->edge = malloc((size_t)(d->ne + 1) * sizeof *d->edge);
    d->face_size = malloc((size_t)(d->nf + 1) * sizeof *d->face_size);
    char *end;
    for (int i = 0; i < 3 * d->nv; i++, p = end) d->v[i] = strtod(p, &end);
    for (int i = 0; i < d->nf; i++) {
        d->face_size[i] = (int)strtol(p, &end, 10);
        for (int k = 0; k <= d->face_size[i]; k++) strtol(end, &end, 10); /* indices, then kind */
        p = end;
    }
    for (int i = 0; i < d->ne; i++)
        for (int k = 0; k < 3; k++, p = end) d->edge[i][k] = (int)strtol(p, &end, 10);
}

static void free_ply(ply_data *d)
{
    free(d->v);
    free(d->edge);
    free(d->face_size);
}

static spn_world *small_web(void)
{
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 5;
    od.radials = 8;
    spn_world *w;
    assert_int_equal(spn_scene_orb(NULL, &od, &w), SPN_OK);
    return w;
}

static char *export_text(const spn_world *w, const spn_export_def *d,
                         spn_status (*fn)(const spn_world *, const spn_export_def *, spn_sink *))
{
    spn_buffer buf = {0};
    spn_sink sink = spn_sink_buffer(&buf);
    assert_int_equal(fn(w, d, &sink), SPN_OK);
    return buf.data;
}

static void test_obj_polylines(void **state)
{
    (void)state;
    spn_world *w = small_web();
    spn_export_def d = spn_export_def_default();
    char *text = export_text(w, &d, spn_export_obj);
    obj_data o;
    read_obj(text, &o);
    assert_int_equal(o.nv, (int)spn_world_particle_count(w));
    for (int i = 0; i < o.nv; i++) {
        spn_vec3 p = spn_world_position(w, (uint32_t)i);
        assert_true(fabs(o.v[3 * i] - p.x) < 1e-9 && fabs(o.v[3 * i + 1] - p.y) < 1e-9 && fabs(o.v[3 * i + 2] - p.z) < 1e-9);
    }
    /* 8 radii, 4 capture rings, 1 frame ring; polyline points - 1 per line = springs. */
    assert_int_equal(o.lines, 8 + 5);
    assert_int_equal(o.line_points - o.lines, (int)spn_world_spring_count(w));
    assert_int_equal(o.objects, 3);
    assert_true(o.max_index <= o.nv);
    free(o.v);
    free(text);
    spn_world_destroy(w);
}

/* Every spring comes back as one PLY edge with its kind. */
static void test_ply_polylines(void **state)
{
    (void)state;
    spn_world *w = small_web();
    spn_export_def d = spn_export_def_default();
    char *text = export_text(w, &d, spn_export_ply);
    ply_data p;
    read_ply(text, &p);
    uint32_t ns = spn_world_spring_count(w);
    assert_int_equal(p.nv, (int)spn_world_particle_count(w));
    assert_int_equal(p.ne, (int)ns);
    assert_int_equal(p.nf, 0);
    for (int i = 0; i < p.nv; i++) assert_true(fabs(p.v[3 * i] - spn_world_position(w, (uint32_t)i).x) < 1e-9);
    bool *seen = calloc(ns, sizeof *seen);
    for (int e = 0; e < p.ne; e++)
        for (uint32_t s = 0; s < ns; s++) {
            spn_spring_info info = spn_world_spring(w, s);
            bool same = ((int)info.a == p.edge[e][0] && (int)info.b == p.edge[e][1]) ||
                        ((int)info.b == p.edge[e][0] && (int)info.a == p.edge[e][1]);
            if (same && !seen[s] && (int)info.tag == p.edge[e][2]) {
                seen[s] = true;
                break;
            }
        }
    for (uint32_t s = 0; s < ns; s++) assert_true(seen[s]);
    free(seen);
    free_ply(&p);
    free(text);
    spn_world_destroy(w);
}

/* A straight sagging chain as one tube: rings around every particle. */
static void test_tubes(void **state)
{
    (void)state;
    spn_world *w;
    assert_int_equal(spn_scene_chain(NULL, spn_v3(0, 0, 0), spn_v3(1, 0.2, 0.1), 10, 1.2, 0.1, 10, 0, &w), SPN_OK);
    spn_export_def d = spn_export_def_default();
    d.tube_radius = 0.01;
    d.tube_sides = 7;
    char *text = export_text(w, &d, spn_export_obj);
    obj_data o;
    read_obj(text, &o);
    assert_int_equal(o.nv, 11 * 7);
    assert_int_equal(o.faces, 10 * 7 + 2);
    assert_int_equal(o.lines, 0);
    for (int i = 0; i < 11; i++) {
        spn_vec3 c = spn_world_position(w, (uint32_t)i), mean = spn_v3(0, 0, 0);
        for (int k = 0; k < 7; k++) {
            spn_vec3 v = spn_v3(o.v[3 * (i * 7 + k)], o.v[3 * (i * 7 + k) + 1], o.v[3 * (i * 7 + k) + 2]);
            assert_true(fabs(spn_v3_len(spn_v3_sub(v, c)) - 0.01) < 1e-7);
            mean = spn_v3_add(mean, spn_v3_scale(v, 1.0 / 7));
        }
        assert_true(spn_v3_len(spn_v3_sub(mean, c)) < 1e-7);
    }
    free(o.v);
    free(text);
    text = export_text(w, &d, spn_export_ply);
    ply_data p;
    read_ply(text, &p);
    assert_int_equal(p.nv, 11 * 7);
    assert_int_equal(p.nf, 10 * 7 + 2);
    assert_int_equal(p.face_size[0], 4);
    free_ply(&p);
    free(text);
    spn_world_destroy(w);
}

/* An importer we did not write (assimp, as used by many DCC tools) reads the
 * OBJ: one mesh per thread kind, named after it, of line primitives, one line
 * per spring; with --tubes, polygon meshes. */
static void test_obj_in_assimp(void **state)
{
    (void)state;
#ifndef HAVE_ASSIMP
    printf("skipped: assimp headers are not installed (libassimp-dev)\n");
    skip();
#else
    spn_world *w = small_web();
    spn_export_def d = spn_export_def_default();
    char path[512];
    snprintf(path, sizeof path, "%s/export_assimp_%ld.obj", SPN_BUILD_DIR, (long)getpid());
    for (int tubes = 0; tubes < 2; tubes++) {
        d.tube_radius = tubes ? 0.001 : 0;
        assert_int_equal(spn_export_file(w, &d, path), SPN_OK);
        const struct aiScene *sc = aiImportFile(path, 0);
        assert_non_null(sc);
        assert_int_equal(sc->mNumMeshes, 3);
        unsigned faces = 0;
        for (unsigned i = 0; i < sc->mNumMeshes; i++) {
            const struct aiMesh *m = sc->mMeshes[i];
            const char *name = m->mName.data;
            assert_true(strcmp(name, "frame") == 0 || strcmp(name, "radius") == 0 || strcmp(name, "capture") == 0);
            assert_int_equal(m->mPrimitiveTypes, tubes ? aiPrimitiveType_POLYGON : aiPrimitiveType_LINE);
            faces += m->mNumFaces;
        }
        if (!tubes) assert_int_equal(faces, spn_world_spring_count(w));
        aiReleaseImport(sc);
    }
    remove(path);
    spn_world_destroy(w);
#endif
}

static int run(const char *cmd) { return system(cmd); }

/* The exported scene renders in povray without a warning, and the web is in
 * the picture: bright pixels on the black background. */
static void test_pov_renders(void **state)
{
    (void)state;
    if (run("command -v povray > /dev/null 2>&1") != 0) {
        printf("skipped: povray is not installed (apt-get install povray)\n");
        skip();
    }
    char dir[512], cmd[2048], path[600];
    snprintf(dir, sizeof dir, "%s/pov_test_XXXXXX", SPN_BUILD_DIR);
    assert_non_null(mkdtemp(dir));
    spn_world *w = small_web();
    spn_export_def d = spn_export_def_default();
    d.render.dew.enabled = true;
    d.render.dew.spacing = 0.01;
    d.render.dew.radius = 0.002;
    d.render.alpha = 0.8;
    assert_int_equal(spn_export_pov_frame(w, &d, dir, 3), SPN_OK);
    snprintf(path, sizeof path, "%s/frame_00003.pov", dir);
    snprintf(cmd, sizeof cmd,
             "cd '%s' && povray +W120 +H120 -D +A0.1 +Oout.png '%s' > log.txt 2>&1 && "
             "! grep -E 'Warning:|Error:|Possible' log.txt",
             dir, path);
    assert_int_equal(run(cmd), 0);
    snprintf(path, sizeof path, "%s/out.png", dir);
    cairo_surface_t *s = cairo_image_surface_create_from_png(path);
    assert_int_equal(cairo_surface_status(s), CAIRO_STATUS_SUCCESS);
    const unsigned char *px = cairo_image_surface_get_data(s);
    int stride = cairo_image_surface_get_stride(s), lit = 0;
    for (int y = 0; y < 120; y++)
        for (int x = 0; x < 120; x++) lit += (px[y * stride + 4 * x + 1] > 60);
    cairo_surface_destroy(s);
    assert_true(lit > 120 * 120 / 50);
    assert_true(lit < 120 * 120 / 2);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(run(cmd), 0);
    spn_world_destroy(w);
}

static void test_bad_exports(void **state)
{
    (void)state;
    spn_world *w = small_web();
    spn_export_def d = spn_export_def_default();
    char path[512];
    snprintf(path, sizeof path, "%s/export_bad_%ld.stl", SPN_BUILD_DIR, (long)getpid());
    assert_int_equal(spn_export_file(w, &d, path), SPN_ERR_INVALID);
    assert_int_equal(access(path, F_OK), -1);
    snprintf(path, sizeof path, "%s/export_bad_%ld.obj", SPN_BUILD_DIR, (long)getpid());
    d.tube_sides = 2;
    assert_int_equal(spn_export_file(w, &d, path), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "tube_sides"));
    assert_int_equal(access(path, F_OK), -1);
    d = spn_export_def_default();
    d.render.background_png = "/nonexistent/sky.png";
    snprintf(path, sizeof path, "%s/export_bad_%ld.pov", SPN_BUILD_DIR, (long)getpid());
    assert_int_equal(spn_export_file(w, &d, path), SPN_ERR_IO);
    assert_int_equal(access(path, F_OK), -1);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_obj_polylines), cmocka_unit_test(test_ply_polylines), cmocka_unit_test(test_tubes),
        cmocka_unit_test(test_obj_in_assimp), cmocka_unit_test(test_pov_renders),
        cmocka_unit_test(test_bad_exports),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

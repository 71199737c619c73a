/* Saving and loading the standard orb web (5k, 100k and 1M particles) as a
 * JSON web file and as a binary one (.spnw), through spn_web_save and
 * spn_web_load: wall seconds, the file's size and the rate. A researcher's
 * one-shot `spinneret settle big.json -o out.json --method equilibrium` on the
 * 1M web spends more in these two calls than in the solve; this measures what
 * each file costs. Every load is checked against the world saved (same
 * counts, same position bits), so a fast wrong reader cannot pass.
 *
 * usage: bench_io [--quick]   (--quick: the 5k web only) */
#include "common/bench_common.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int same_web(const spn_world *a, const spn_world *b)
{
    uint32_t n = spn_world_particle_count(a);
    if (n != spn_world_particle_count(b) || spn_world_spring_count(a) != spn_world_spring_count(b)) return 0;
    return memcmp(spn_world_positions(a), spn_world_positions(b), n * sizeof(spn_vec3)) == 0;
}

static int measure(const spn_world *w, const char *size, const char *dir, const char *ext)
{
    char path[512];
    snprintf(path, sizeof path, "%s/web.%s", dir, ext);
    double load_avg = bench_load_average(), t0 = bench_now();
    if (spn_web_save(w, path) != SPN_OK) {
        fprintf(stderr, "bench_io: %s\n", spn_last_error());
        return 1;
    }
    double t1 = bench_now();
    spn_world *back = NULL;
    spn_status st = spn_web_load(path, &back);
    double t2 = bench_now();
    struct stat sb;
    int bad = st != SPN_OK || !same_web(w, back) || stat(path, &sb) != 0;
    if (bad) fprintf(stderr, "bench_io: %s did not read back: %s\n", path, st != SPN_OK ? spn_last_error() : "differs");
    else {
        double mb = (double)sb.st_size / 1e6;
        printf("{\"bench\":\"web_io\",\"scene\":\"orb\",\"size\":\"%s\",\"format\":\"%s\",\"particles\":%u,"
               "\"springs\":%u,\"file_mb\":%.1f,\"save_s\":%.3f,\"load_s\":%.3f,\"save_mb_per_s\":%.0f,"
               "\"load_mb_per_s\":%.0f,\"load_avg\":%.2f}\n",
               size, ext, spn_world_particle_count(w), spn_world_spring_count(w), mb, t1 - t0, t2 - t1,
               mb / (t1 - t0), mb / (t2 - t1), load_avg);
        fflush(stdout);
    }
    spn_world_destroy(back);
    remove(path);
    return bad;
}

int main(int argc, char **argv)
{
    int quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
    if (argc > 2 || (argc == 2 && !quick)) {
        fprintf(stderr, "usage: bench_io [--quick]\n");
        return 2;
    }
    char dir[] = "/tmp/spn-bench-io-XXXXXX";
    if (!mkdtemp(dir)) {
        perror("bench_io: mkdtemp");
        return 1;
    }
    int bad = 0;
    for (int s = 0; s < (quick ? 1 : 3) && !bad; s++) {
        spn_world *w = bench_orb(&BENCH_ORB_SIZES[s], 1);
        bad = measure(w, BENCH_ORB_SIZES[s].name, dir, "json") || measure(w, BENCH_ORB_SIZES[s].name, dir, "spnw");
        spn_world_destroy(w);
    }
    rmdir(dir);
    return bad;
}

/* bench_inscribe: "PIG" written into README's physical web (thesis values,
 * anchors -0.4,0.42; 0.42,0.38; 0.4,-0.45; -0.42,-0.38, built and settled
 * as `spinneret build ... --settle` does), as `spinneret inscribe web.json
 * --text PIG --emphasis E --solver implicit` does it: the library's defaults
 * (docs/inscription.md, "The web stays physical": the rest state solved for
 * after editing, stepped with SPN_SETTLE_DRAG where that falls short). One
 * JSON line per emphasis: how the web came to rest after editing, Newton
 * steps, implicit steps and simulated time, the residual, and wall and CPU
 * time of spn_inscribe (scoring, edits and both settles), 1 thread.
 *
 * --quick: the plain method and cross-hatch only. --before: the same with
 * the settle of before the thirty-third session (stepped, the web's own
 * drag), 74 s of CPU for the fill on the Zen 4; not run by make bench. */
#include "common/bench_common.h"

#include <spinneret/spinneret.h>

#include <stdio.h>
#include <string.h>

static spn_world *physical_web(void)
{
    const spn_vec3 anchors[] = {{-0.4, 0.42, 0}, {0.42, 0.38, 0}, {0.4, -0.45, 0}, {-0.42, -0.38, 0}};
    spn_physical_def d = spn_physical_def_default();
    d.anchors = anchors;
    d.anchor_count = 4;
    d.world.threads = 1;
    spn_world *w = NULL;
    spn_settle_report r;
    if (spn_web_build_physical(&d, &w) != SPN_OK || spn_web_settle(w, 30, &r) != SPN_OK) {
        fprintf(stderr, "bench_inscribe: %s\n", spn_last_error());
        spn_world_destroy(w);
        return NULL;
    }
    return w;
}

static int run(const spn_world *web, spn_emphasis emphasis, int before)
{
    spn_world *w = spn_world_clone(web);
    spn_target *t = NULL;
    spn_text_def td = spn_text_def_default();
    td.text = "PIG";
    spn_status st = w ? spn_target_create(w, 1200, &t) : SPN_ERR_NOMEM;
    if (st == SPN_OK) st = spn_target_text(t, w, &td);
    spn_inscribe_def d = spn_inscribe_def_default();
    d.emphasis = emphasis;
    if (before) d.settle_solve = false, d.settle_def.drag = 0;
    spn_inscribe_report r;
    double wall = 0, cpu = 0;
    if (st == SPN_OK) {
        spn_world_set_integrator(w, SPN_INTEGRATOR_IMPLICIT);
        const double wall0 = bench_now(), cpu0 = bench_cpu_now();
        st = spn_inscribe(&w, t, &d, &r);
        wall = bench_now() - wall0, cpu = bench_cpu_now() - cpu0;
    }
    if (st != SPN_OK) {
        fprintf(stderr, "bench_inscribe: %s\n", spn_last_error());
        spn_target_destroy(t);
        spn_world_destroy(w);
        return 1;
    }
    const spn_settle_report *a = &r.after;
    printf("{\"bench\":\"inscribe\",\"web\":\"physical\",\"text\":\"PIG\",\"emphasis\":\"%s\",\"settle\":\"%s\","
           "\"particles\":%u,\"springs\":%u,\"threads\":1,\"how\":\"%s\",\"converged\":%s,\"newton_steps\":%d,"
           "\"steps\":%llu,\"simulated_s\":%.4g,\"residual_n\":%.3g,\"ms\":%.1f,\"cpu_ms\":%.1f,"
           "\"load_average\":%.2f}\n",
           spn_emphasis_name(emphasis), before ? "stepped, own drag" : "default", spn_world_particle_count(w),
           spn_world_spring_count(w), a->steps ? "stepped" : "solved",
           a->reason == SPN_SETTLE_CONVERGED ? "true" : "false", a->newton_steps, (unsigned long long)a->steps, a->time,
           a->residual, 1e3 * wall, 1e3 * cpu, bench_load_average());
    fflush(stdout);
    spn_target_destroy(t);
    spn_world_destroy(w);
    return 0;
}

int main(int argc, char **argv)
{
    const int quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
    const int before = argc > 1 && strcmp(argv[1], "--before") == 0;
    const spn_emphasis modes[] = {SPN_EMPHASIS_NONE, SPN_EMPHASIS_CROSSHATCH, SPN_EMPHASIS_OUTLINE, SPN_EMPHASIS_FILL};
    spn_world *web = physical_web();
    if (!web) return 1;
    int failed = 0;
    for (int i = 0; i < (quick ? 2 : 4) && !failed; i++)
        failed = run(web, modes[i], before);
    spn_world_destroy(web);
    return failed;
}

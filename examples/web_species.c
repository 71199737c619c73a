/* Build a garden-spider web, measure it, and write it out: the web builders'
 * API in one page. Run: ./example_web_species [seed] */
#include <spinneret/spinneret.h>

#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    spn_species_def def = spn_species_def_preset(SPN_SPECIES_ARANEUS);
    def.seed = argc > 1 ? strtoull(argv[1], NULL, 10) : 1; /* another individual per seed */
    spn_world *web = NULL;
    if (spn_web_build_species(&def, &web) != SPN_OK) {
        fprintf(stderr, "build: %s\n", spn_last_error());
        return 1;
    }
    /* Every spring knows its thread kind, stage and place in the build. */
    spn_spring_info first = spn_world_spring(web, 0);
    printf("first thread laid: %s (stage %s)\n", spn_thread_kind_name(first.tag), spn_web_stage_name(first.stage));

    spn_web_measures m;
    spn_web_measure(web, &m);
    spn_sink out = spn_sink_file(stdout);
    spn_web_measures_write(&m, false, &out);

    spn_status st = spn_web_save(web, "araneus.json");
    if (st != SPN_OK) fprintf(stderr, "save: %s\n", spn_last_error());
    spn_world_destroy(web);
    return st == SPN_OK ? 0 : 1;
}

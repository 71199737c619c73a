/* Species presets: the figures that make a web recognisably of a species
 * (docs/species.md gives each with its source), and the seed's natural
 * variation. The web itself is woven by species_web.c. */
#include "web_internal.h"

#include <string.h>

static const char *names[SPN_SPECIES_COUNT] = {"generic", "araneus", "zilla", "argiope", "zygiella"};

const char *spn_species_name(spn_species species)
{
    return (unsigned)species < SPN_SPECIES_COUNT ? names[species] : "unknown";
}

spn_status spn_species_parse(const char *name, spn_species *out)
{
    for (int i = 0; i < SPN_SPECIES_COUNT; i++)
        if (strcmp(name, names[i]) == 0) {
            *out = (spn_species)i;
            return SPN_OK;
        }
    return spn_error(SPN_ERR_INVALID, "unknown species '%s' (choose generic, araneus, zilla, argiope or zygiella)", name);
}

spn_species_def spn_species_def_preset(spn_species species)
{
    spn_species_def d;
    memset(&d, 0, sizeof d);
    d.species = species;
    d.materials = spn_web_materials_preset(SPN_MATERIAL_SILK);
    d.size = 0.30;
    d.radii = 28;
    d.hub_radius = 0.010;
    d.free_zone = 0.012;
    d.mesh_inner = 0.0030;
    d.mesh_outer = 0.0050;
    d.hub_offset = 0.06;
    d.contraction = 0.1;
    d.margin = 0.006;
    d.aux_spiral = true;
    d.open_sector_angle = 0.75 * SPN_PI; /* upper left */
    d.jitter = 0.08;
    d.segment = 0.01;
    d.strains = spn_web_strains_preset(SPN_MATERIAL_SILK);
    d.form_find = true;
    d.seed = 1;
    d.world = spn_world_def_default();
    switch (species) {
    case SPN_SPECIES_ARANEUS: /* Witt et al. 1968; Zschokke 2011; Herberstein & Heiling 1999 */
        d.size = 0.26;
        d.radii = 30;
        d.hub_radius = 0.012;
        d.free_zone = 0.015;
        d.mesh_inner = 0.0030;
        d.mesh_outer = 0.0050;
        d.hub_offset = 0.09;
        break;
    case SPN_SPECIES_ZILLA: /* Mehla 2005 fig. 3.4; Jones 1978 (BAS newsletter 21) */
        d.size = 0.20;
        d.radii = 38;
        d.hub_radius = 0.012;
        d.free_zone = 0.006;
        d.mesh_inner = 0.0014;
        d.mesh_outer = 0.0020;
        d.hub_offset = 0.03;
        d.contraction = 0.05;
        break;
    case SPN_SPECIES_ARGIOPE: /* Herberstein et al. 2000; Blackledge & Gillespie 2002 */
        d.size = 0.40;
        d.radii = 32;
        d.hub_radius = 0.015;
        d.free_zone = 0.012;
        d.mesh_inner = 0.0030;
        d.mesh_outer = 0.0055;
        d.hub_offset = 0.08;
        d.stabilimentum = true;
        break;
    case SPN_SPECIES_ZYGIELLA: /* Wikipedia "Zygiella x-notata" (25-30 radii); Thévenard et al. */
        d.size = 0.20;
        d.radii = 28;
        d.hub_radius = 0.008;
        d.free_zone = 0.008;
        d.mesh_inner = 0.0018;
        d.mesh_outer = 0.0030;
        d.hub_offset = 0.10;
        d.open_sector = 2 * 2 * SPN_PI / 28;
        break;
    default: break;
    }
    return d;
}

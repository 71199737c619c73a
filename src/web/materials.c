/* Thread materials: the thesis preset and measured silk.
 *
 * Thesis (Mehla 2005, figs. 5.5, 5.10 and sec. 5.2.1): outer frame springs
 * k = 0.001 N/m at rest 2 mm, inner frame k = 0.001 N/m at rest 15 mm, spokes
 * k = 0.01 N/m at rest 3 mm, every particle 10 ug (1e-8 kg), air friction
 * 1e-8 N s/m per particle. As materials (k = EA / r, particle mass = density
 * * r for a chain's inner particle) that is EA = k r and density = 1e-8 kg / r,
 * so the thesis' own lengths give back exactly its k and masses. The thesis
 * gives no values for the spiral; it gets 3% of the spokes' stiffness so
 * that its pull does not bend the spokes (capture silk is the compliant one).
 *
 * Silk (docs/species.md has the sources): major ampullate (dragline) silk,
 * E = 10 GPa, density 1300 kg/m^3, radii and frame threads of about 4 um and
 * 5 um diameter; viscid capture silk, E = 3 MPa on a 2 um core carrying
 * aqueous glue droplets that make the thread some ten times heavier than its
 * core (Gosline et al. 1999; Vollrath & Edmonds 1989; Denny 1976). */
#include "web_internal.h"

#include <string.h>

static spn_thread_material mat(double ea, double density, double diameter, double zeta)
{
    spn_thread_material m = {ea, density, diameter, zeta};
    return m;
}

static spn_thread_material silk(double modulus, double diameter, double density_factor, double zeta)
{
    double area = SPN_PI * diameter * diameter / 4;
    return mat(modulus * area, 1300.0 * area * density_factor, diameter, zeta);
}

spn_web_materials spn_web_materials_preset(spn_material_preset preset)
{
    spn_web_materials m;
    memset(&m, 0, sizeof m);
    if (preset == SPN_MATERIAL_SILK) {
        spn_thread_material frame = silk(10e9, 5e-6, 1, 0.05), radius = silk(10e9, 4e-6, 1, 0.05);
        for (int k = 0; k < SPN_WEB_KINDS; k++) m.kind[k] = radius;
        m.kind[SPN_THREAD_ANCHOR] = m.kind[SPN_THREAD_FRAME] = m.kind[SPN_THREAD_BRIDGE] = frame;
        m.kind[SPN_THREAD_HUB] = m.kind[SPN_THREAD_AUX_SPIRAL] = silk(10e9, 2e-6, 1, 0.05);
        m.kind[SPN_THREAD_CAPTURE] = silk(3e6, 2e-6, 10, 0.05);
        /* A ribbon of many fine aciniform threads, laid loose: it pulls like
         * capture silk, not like a 3 um fibre (1 MPa on its 3 um width; laid at
         * the capture spiral's strain, spn__web_prestrains). As a solid 10 GPa
         * thread at the radii's 2% it pinched the radii it joins together and
         * rested at strains of 1e-7 at the slack point, where the settle's
         * Newton solve crawled: Argiope webs stepped to rest in 3-5 s instead
         * of solving in 0.1 s (docs/web-builders.md, "Settling"). */
        m.kind[SPN_THREAD_STABILIMENTUM] = silk(1e6, 3e-6, 4, 0.05);
        m.kind[SPN_THREAD_SIGNAL] = silk(10e9, 5e-6, 1, 0.05);
        return m;
    }
    const double particle = 1e-8, zeta = 0.05;
    spn_thread_material spoke = mat(0.01 * 0.003, particle / 0.003, 2e-6, zeta);
    for (int k = 0; k < SPN_WEB_KINDS; k++) m.kind[k] = spoke;
    /* The thesis' frame constants cannot carry its spokes: a hundred spokes
     * at 4e-5 N each need a frame tension near 4e-3 N, and at k = 0.001 N/m
     * the frame and anchor threads stretch until the web collapses onto its
     * hub. Real frame threads are several times thicker than radii; so are
     * these: 700 times the stiffness and 30 times the
     * mass of the thesis' values (docs/web-builders.md). */
    const double stiffer = 700, heavier = 30;
    m.kind[SPN_THREAD_ANCHOR] = m.kind[SPN_THREAD_BRIDGE] =
        mat(stiffer * 0.001 * 0.002, heavier * particle / 0.002, 3e-6, zeta);
    m.kind[SPN_THREAD_FRAME] = mat(stiffer * 0.001 * 0.015, heavier * particle / 0.015, 3e-6, zeta);
    /* The hub ring gathers every secondary spoke: it is many strands thick. */
    m.kind[SPN_THREAD_HUB] = mat(15 * 0.01 * 0.003, 5 * particle / 0.003, 4e-6, zeta);
    /* The thesis gives every particle 10 ug, and the spiral adds no particles
     * (it joins spoke masses), so its threads carry almost no mass of their own. */
    m.kind[SPN_THREAD_CAPTURE] = m.kind[SPN_THREAD_AUX_SPIRAL] = mat(0.0003 * 0.003, 0.05 * particle / 0.003, 1.5e-6, zeta);
    /* Argiope's band pulls like the capture spiral, as in silk (above): with
     * the spokes' stiffness at the capture spiral's strain it pinched the
     * radii together and curled. */
    m.kind[SPN_THREAD_STABILIMENTUM] = m.kind[SPN_THREAD_CAPTURE];
    return m;
}

spn_web_strains spn_web_strains_preset(spn_material_preset preset)
{
    spn_web_strains s;
    if (preset == SPN_MATERIAL_SILK) {
        /* Frame and mooring threads carry several times the radii's tension
         * (Wirth & Barth 1992, forces in the orb web of Araneus diadematus);
         * laid with the radii's strain, the frame would have to stretch far
         * before the web could balance, and a stiff-silk solver would crawl
         * there. The mooring threads hold the frame's corners out against the
         * radii: laid at 5 times the radii's old 2% they let the corners in
         * until the radii kept a tenth or less of theirs (docs/web-builders.md,
         * "Settling"); at 10 times, of four strands (SPN__MOORING_STRANDS),
         * they keep them taut. The radii are laid at 0.5% on the shape the
         * form finding gives (form_find.c): what they kept at rest when laid
         * at 2% on the designed one (0.1-0.5% on the species webs, 0.2% on
         * the geometric web). At 2% they would pull the frame in by a tenth of
         * the web's width; at 0.3-1% the species webs rest within 0.3-1.4%
         * (median particle) of where they rested before ("The woven web's
         * shape"). */
        s.radii = 0.005, s.capture = 0.3, s.frame = 0.08, s.anchor = 0.2;
        return s;
    }
    /* The thesis' placements over its rest lengths (spn_physical_def_default):
     * spokes 7 on 3 mm, inner frame 20 on 15 mm, outer frame 5 on 2 mm, and the
     * spiral's extension. Its springs are soft for their mass (a 3 mm spoke
     * of 10 ug at 0.01 N/m): laid at silk's 2% a woven web hung below its own
     * frame, and a geometric web collapsed onto its lower side
     * (docs/web-builders.md, "The thesis preset"). */
    s.radii = 7.0 / 3 - 1, s.capture = 0.75, s.frame = 20.0 / 15 - 1, s.anchor = 5.0 / 2 - 1;
    return s;
}

static const char *preset_names[] = {"thesis", "silk"};

const char *spn_material_preset_name(spn_material_preset preset)
{
    return (unsigned)preset < 2 ? preset_names[preset] : "unknown";
}

spn_status spn_material_preset_parse(const char *name, spn_material_preset *out)
{
    for (int i = 0; i < 2; i++)
        if (strcmp(name, preset_names[i]) == 0) {
            *out = (spn_material_preset)i;
            return SPN_OK;
        }
    return spn_error(SPN_ERR_INVALID, "unknown material preset '%s' (choose thesis or silk)", name);
}

/* The impact report as JSON: outcome per prey, where the prey's energy went
 * (per thread kind: elastic now, damping, broken; air drag; the web's motion)
 * and the threads broken per kind. Energies in joules, fractions of the prey's
 * lost kinetic energy. */
#include "anim_internal.h"

#include <math.h>

static const char *kind_name(uint32_t tag)
{
    const char *n = spn_thread_kind_name(tag);
    return n ? n : "other";
}

static double absorbed(const spn_kind_energy *k) { return k->elastic + k->damping + k->plastic + k->broken; }

static spn_status write_prey(const spn_impact_report *r, spn_sink *s)
{
    spn_status st = spn_sink_printf(s, "  \"prey\": [");
    for (int p = 0; p < r->nprey && p < 8 && st == SPN_OK; p++)
        st = spn_sink_printf(s, "%s{\"outcome\": \"%s\"}", p ? ", " : "", spn_prey_outcome_name(r->outcome[p]));
    if (st == SPN_OK) st = spn_sink_printf(s, "],\n");
    return st;
}

static spn_status write_kinds(const spn_impact_report *r, spn_sink *s, double lost)
{
    spn_status st = spn_sink_printf(s, "  \"threads\": {");
    for (int i = 0; i < r->nkinds && st == SPN_OK; i++) {
        const spn_kind_energy *k = &r->kinds[i];
        st = spn_sink_printf(s,
                             "%s\n    \"%s\": {\"absorbed\": %.9g, \"fraction\": %.6f, \"elastic\": %.9g, "
                             "\"damping\": %.9g, \"plastic\": %.9g, \"broken_energy\": %.9g, \"broken\": %u}",
                             i ? "," : "", kind_name(k->tag), absorbed(k), lost > 0 ? absorbed(k) / lost : 0,
                             k->elastic, k->damping, k->plastic, k->broken, k->breaks);
    }
    if (st == SPN_OK) st = spn_sink_printf(s, "\n  },\n");
    return st;
}

/* The partition when the strike ended: what stopped (or slowed) the prey. */
static spn_status write_strike(const spn_impact_report *r, spn_sink *s)
{
    double lost = r->strike_prey_kinetic_lost;
    spn_status st = spn_sink_printf(s, "  \"strike\": {\"ended\": %s, \"time\": %.6g, \"prey_kinetic_lost\": %.9g",
                                    r->strike_time >= 0 ? "true" : "false", r->strike_time, lost);
    for (int i = 0; i < r->nkinds && st == SPN_OK; i++)
        st = spn_sink_printf(s, ", \"%s\": %.6f", kind_name(r->kinds[i].tag), lost > 0 ? r->strike_absorbed[i] / lost : 0);
    if (st == SPN_OK)
        st = spn_sink_printf(s, ",\n    \"air_drag\": %.6f, \"glue\": %.6f, \"web_kinetic\": %.6f},\n",
                             lost > 0 ? r->strike_air / lost : 0, lost > 0 ? r->strike_glue / lost : 0,
                             lost > 0 ? r->strike_web_kinetic / lost : 0);
    return st;
}

spn_status spn_impact_report_write(const spn_impact_report *r, spn_sink *s)
{
    double lost = r->prey_kinetic_start - r->prey_kinetic_end;
    double air = r->air_work == 0 ? 0 : -r->air_work;
    spn_status st = spn_sink_printf(s, "{\n");
    if (st == SPN_OK) st = write_prey(r, s);
    if (st == SPN_OK)
        st = spn_sink_printf(s,
                             "  \"energy\": {\"prey_kinetic_start\": %.9g, \"prey_kinetic_end\": %.9g, "
                             "\"prey_kinetic_lost\": %.9g,\n    \"air_drag\": %.9g, \"air_drag_fraction\": %.6f, "
                             "\"web_kinetic\": %.9g, \"viscous\": %.9g, \"solver\": %.9g, \"glue\": %.9g, \"glue_droplets_holding\": %d, \"glue_strength_holding\": %.6g, \"wind_work\": %.9g, \"contact\": %.9g,\n"
                             "    \"total_start\": %.9g, \"total_end\": %.9g, \"balance_error\": %.9g, "
                             "\"balance_error_relative\": %.6g},\n",
                             r->prey_kinetic_start, r->prey_kinetic_end, lost, air, lost > 0 ? air / lost : 0,
                             r->web_kinetic, r->viscous, r->solver, r->glue, r->glue_held, r->glue_strength_held, r->wind_work, r->contact_energy, r->total_start, r->total_now,
                             r->balance_error, r->prey_kinetic_start > 0 ? r->balance_error / r->prey_kinetic_start : 0);
    if (st == SPN_OK) st = write_kinds(r, s, lost);
    if (st == SPN_OK) st = write_strike(r, s);
    if (st == SPN_OK) st = spn_sink_printf(s, "  \"broken\": {");
    int first = 1;
    for (int i = 0; i < r->nkinds && st == SPN_OK; i++) {
        if (!r->kinds[i].breaks) continue;
        st = spn_sink_printf(s, "%s\"%s\": %u", first ? "" : ", ", kind_name(r->kinds[i].tag), r->kinds[i].breaks);
        first = 0;
    }
    if (st == SPN_OK)
        st = spn_sink_printf(s,
                             "},\n  \"broken_total\": %u,\n  \"damage\": {\"web_radius\": %.6g, "
                             "\"break_distance_max\": %.6g, \"break_distance_mean\": %.6g}\n}\n",
                             r->breaks, r->web_radius, r->break_distance_max, r->break_distance_mean);
    return st;
}

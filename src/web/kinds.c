/* Thread kind names, as written in web files and accepted on the command line. */
#include "spinneret/web.h"

#include <string.h>

static const struct {
    uint32_t tag;
    const char *name;
} kinds[] = {
    {SPN_THREAD_GENERIC, "generic"},       {SPN_THREAD_ANCHOR, "anchor"},
    {SPN_THREAD_FRAME, "frame"},           {SPN_THREAD_RADIUS, "radius"},
    {SPN_THREAD_HUB, "hub"},               {SPN_THREAD_AUX_SPIRAL, "aux-spiral"},
    {SPN_THREAD_CAPTURE, "capture"},       {SPN_THREAD_INSCRIPTION, "inscription"},
    {SPN_THREAD_STABILIMENTUM, "stabilimentum"}, {SPN_THREAD_SIGNAL, "signal"},
    {SPN_THREAD_BRIDGE, "bridge"},         {SPN_THREAD_STRETCH, "stretch"},
    {SPN_THREAD_BEND, "bend"},             {SPN_THREAD_VICINITY, "vicinity"},
    {SPN_THREAD_SHOT, "shot"},
};

const char *spn_thread_kind_name(uint32_t tag)
{
    for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++)
        if (kinds[i].tag == tag) return kinds[i].name;
    return NULL;
}

spn_status spn_thread_kind_parse(const char *name, uint32_t *tag)
{
    for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++)
        if (strcmp(kinds[i].name, name) == 0) {
            *tag = kinds[i].tag;
            return SPN_OK;
        }
    return spn_error(SPN_ERR_INVALID, "unknown thread kind '%s'", name);
}

static const char *stage_names[SPN_STAGE_COUNT] = {"frame", "radii", "aux-spiral", "capture", "decoration"};

const char *spn_web_stage_name(uint32_t stage) { return stage < SPN_STAGE_COUNT ? stage_names[stage] : NULL; }

/* Orb webs: thread kinds (the tags springs carry) and the web builders.
 * Physics knows only numeric tags; these give them meaning for builders,
 * renderers and exporters. */
#ifndef SPINNERET_WEB_H
#define SPINNERET_WEB_H

#include "world.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Thread kinds, stored as spring tags. Values are part of the web file format.
typedef enum spn_thread_kind {
    SPN_THREAD_GENERIC = 0,       ///< untagged spring
    SPN_THREAD_ANCHOR = 1,        ///< outer frame: anchor to frame (mooring threads)
    SPN_THREAD_FRAME = 2,         ///< inner frame
    SPN_THREAD_RADIUS = 3,        ///< spokes / radii
    SPN_THREAD_HUB = 4,           ///< hub mesh
    SPN_THREAD_AUX_SPIRAL = 5,    ///< auxiliary (temporary) spiral
    SPN_THREAD_CAPTURE = 6,       ///< capture (sticky) spiral
    SPN_THREAD_INSCRIPTION = 7,   ///< threads added by inscription
    SPN_THREAD_STABILIMENTUM = 8, ///< Argiope's zig-zag silk band
    SPN_THREAD_SIGNAL = 9,        ///< Zygiella's signal thread
    SPN_THREAD_BRIDGE = 10,       ///< bridge line
    SPN_THREAD_STRETCH = 16,      ///< mesh factory: edge spring
    SPN_THREAD_BEND = 17,         ///< mesh factory: across two triangles
    SPN_THREAD_VICINITY = 18,     ///< mesh factory: near vertices
    SPN_THREAD_SHOT = 20          ///< web-shooting strand
} spn_thread_kind;

/// Particle tags used by the builders.
typedef enum spn_particle_kind {
    SPN_PARTICLE_GENERIC = 0,
    SPN_PARTICLE_ANCHOR = 1,      ///< fixed attachment point
    SPN_PARTICLE_FRAME = 2,
    SPN_PARTICLE_HUB = 3,
    SPN_PARTICLE_RADIUS = 4,
    SPN_PARTICLE_SPIRAL = 5
} spn_particle_kind;

/// "anchor", "frame", ..., or NULL for an unknown tag.
SPN_API const char *spn_thread_kind_name(uint32_t tag);
/// Parse a thread kind name; SPN_ERR_INVALID when unknown.
SPN_API spn_status spn_thread_kind_parse(const char *name, uint32_t *tag);

#ifdef __cplusplus
}
#endif
#endif

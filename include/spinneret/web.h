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

/* ==== Web builders ====================================================== */

/// Construction stages, stored on every spring (spn_spring_def.stage) in the
/// order a spider lays them; `order` numbers springs within the whole build.
typedef enum spn_web_stage {
    SPN_STAGE_FRAME = 0,       ///< bridge, anchor (mooring) and frame threads
    SPN_STAGE_RADII = 1,       ///< radii and hub
    SPN_STAGE_AUX_SPIRAL = 2,  ///< auxiliary (temporary) spiral
    SPN_STAGE_CAPTURE = 3,     ///< capture (sticky) spiral
    SPN_STAGE_DECORATION = 4,  ///< stabilimentum, signal thread
    SPN_STAGE_COUNT
} spn_web_stage;

/// "frame", "radii", "aux-spiral", "capture", "decoration", or NULL.
SPN_API const char *spn_web_stage_name(uint32_t stage);

/// Number of thread kinds a materials table covers (tags 0 .. SPN_THREAD_BRIDGE).
#define SPN_WEB_KINDS 11
/// Most anchors a builder takes.
#define SPN_WEB_MAX_ANCHORS 64

/// A thread's material (DESIGN, "thread material"): a segment of rest length r
/// gets k = ea / r, mass linear_density * r shared by its ends, and axial
/// damping kd = damping_ratio * 2 sqrt(k m_seg).
typedef struct spn_thread_material {
    double ea;             ///< axial stiffness E*A [N]
    double linear_density; ///< mass per length [kg/m]
    double diameter;       ///< [m], for drawing and air drag
    double damping_ratio;  ///< fraction of critical damping per segment
} spn_thread_material;

/// Materials per thread kind (index = spn_thread_kind, below SPN_WEB_KINDS).
typedef struct spn_web_materials {
    spn_thread_material kind[SPN_WEB_KINDS];
} spn_web_materials;

typedef enum spn_material_preset {
    SPN_MATERIAL_THESIS = 0, ///< Mehla 2005 sec. 5.2.1: k = 0.001 / 0.01 N/m, 10 ug particles
    SPN_MATERIAL_SILK        ///< measured silk: dragline frame and radii, viscid capture spiral
} spn_material_preset;

SPN_API spn_web_materials spn_web_materials_preset(spn_material_preset preset);

/// The strains the woven builders (geometric, species) lay each kind of thread
/// at: length over rest length, minus 1, each in [0, 4].
typedef struct spn_web_strains {
    double radii;   ///< radii, hub, signal and bridge threads (and any kind not named below)
    double capture; ///< capture spiral, and Argiope's stabilimentum, which pulls like it
    double frame;   ///< frame threads: sides and arches
    double anchor;  ///< mooring threads from the frame to the anchors
} spn_web_strains;

/// The strains that go with a material preset. Silk: radii 0.5%, capture 30%,
/// frame 8%, moorings 20% (frame and moorings carry several times the radii's
/// tension; the radii rest at 0.5% on the shape the form finding gives, what
/// they kept at rest when laid at 2% on the designed one). Thesis: Mehla's
/// own over-extensions (placement over rest length: spokes 7 on 3 mm, 133%;
/// spiral 75%; inner frame 20 on 15 mm, 33%; outer frame 5 on 2 mm, 150%),
/// which its soft, heavy springs need to hang taut (laid at silk's strains
/// they sag below their own frame).
SPN_API spn_web_strains spn_web_strains_preset(spn_material_preset preset);
/// "thesis" or "silk"; SPN_ERR_INVALID naming the choices otherwise.
SPN_API spn_status spn_material_preset_parse(const char *name, spn_material_preset *out);
SPN_API const char *spn_material_preset_name(spn_material_preset preset);

/// Mehla's physical construction (sec. 5.2, figs. 5.5, 5.10, 5.15, 5.16).
/// Lengths in metres; the thesis' defaults are in mm (1 unit = 1 mm).
/// Strands are chains of masses laid `placement` apart with springs of rest
/// length `rest`, i.e. over-extended by placement/rest - 1 so they settle taut.
typedef struct spn_physical_def {
    const spn_vec3 *anchors;   ///< at least 3, in order around the web
    int anchor_count;
    spn_web_materials materials; ///< default: the thesis preset
    double move_outer;         ///< inner-frame points move toward the centre by this [m], default 0.06
    double outer_placement;    ///< outer frame (anchor threads): mass spacing, default 5 mm
    double outer_rest;         ///< outer frame spring rest length, default 2 mm
    double frame_placement;    ///< inner frame mass spacing, default 20 mm (sets the spoke count)
    double frame_rest;         ///< default 15 mm
    double spoke_placement;    ///< spoke mass spacing, default 7 mm (sets the spiral density)
    double spoke_rest;         ///< default 3 mm
    double spiral_extension;   ///< capture spiral laid this fraction beyond rest, default 0.75
    double frame_bow;          ///< inward sag of each inner-frame side from the radial force, as
                               ///< a fraction of its length (fig. 5.8), default 0.04
    double hub_radius;         ///< ring where secondary spokes meet the hub [m], default 0.02
    double free_zone;          ///< gap between the hub ring and the spiral [m], default 0.02
    int spiral_density;        ///< SPIRAL_DENSITY: fill while a spoke has more uncovered masses, default 5
    bool provot;               ///< lay strands at rest length and let the world's Provot limit
                               ///< keep them taut (the alternative the thesis compared)
    double provot_max_strain;  ///< with `provot`: the world's limit, default 0.1
    uint64_t seed;             ///< default 1
    spn_world_def world;       ///< the world to build into (drag, integrator, ...)
} spn_physical_def;

SPN_API spn_physical_def spn_physical_def_default(void);
SPN_API spn_status spn_web_build_physical(const spn_physical_def *def, spn_world **out);

/// The geometric construction of the Japanese thesis (2011, sec. 3, eqs. 3.1-3.18),
/// then divided into springs. Every symbol of the thesis is a field with its range.
typedef struct spn_geometric_def {
    const spn_vec3 *anchors;   ///< P_i: 3 .. SPN_WEB_MAX_ANCHORS, in order around the web
    int anchor_count;
    spn_web_materials materials; ///< default: the silk preset (another preset: set `strains` to its own)
    double t;                  ///< attachment points P' = (1-t)P + tG, t in [0.1, 0.2], default 0.15
    double s;                  ///< arch ends Q, R at s along the frame, s in [0.25, 0.30], default 0.28
    int u;                     ///< radii on the longest arch, U in [1, 3], default 3
    int v;                     ///< radii on the longest frame side, V in [4, 8], default 8
    double r_min, r_max;       ///< jitter r in [0.3, 0.7], default 0.3 .. 0.7
    double m;                  ///< contraction rate m in [0, 0.6], default 0.1
    double m_prime;            ///< m' (thesis: 0.2), in [0, 0.5]: inner edge of the capture spiral
    int k;                     ///< capture-spiral turns K in [5, 45], default 15
    double segment;            ///< longest spring when lines are divided [m], default 0.01
    spn_web_strains strains;   ///< how far beyond rest each thread is laid; default: silk's
    bool form_find;            ///< default true: find the web's shape with every thread but frame and
                               ///< moorings pulling at its laid tension, then lay them on it
                               ///< (docs/web-builders.md, "The woven web's shape"); false: as designed.
                               ///< Webs of more than 1,500,000 particles, and webs whose solve falls
                               ///< short, are left as designed: metadata "form_found" says which.
    uint64_t seed;             ///< default 1
    spn_world_def world;
} spn_geometric_def;

SPN_API spn_geometric_def spn_geometric_def_default(void);
SPN_API spn_status spn_web_build_geometric(const spn_geometric_def *def, spn_world **out);

/// Species whose webs the presets imitate (docs/species.md gives the sources).
typedef enum spn_species {
    SPN_SPECIES_GENERIC = 0,
    SPN_SPECIES_ARANEUS,   ///< Araneus diadematus, garden cross spider
    SPN_SPECIES_ZILLA,     ///< Zilla diodia: fine, near-circular mesh
    SPN_SPECIES_ARGIOPE,   ///< Argiope (bruennichi / aurantia): zig-zag stabilimentum
    SPN_SPECIES_ZYGIELLA,  ///< Zygiella x-notata: open sector with a signal thread
    SPN_SPECIES_COUNT
} spn_species;

SPN_API const char *spn_species_name(spn_species species);
SPN_API spn_status spn_species_parse(const char *name, spn_species *out);

/// A species web: the geometric frame (Japanese thesis) with radii, hub, free
/// zone, auxiliary and capture spirals laid as the species lays them. The
/// preset fills every field with the species' published figures; the seed
/// draws the natural variation.
typedef struct spn_species_def {
    spn_species species;
    const spn_vec3 *anchors;   ///< NULL: the species' typical site (anchors around a web of `size`)
    int anchor_count;
    double size;               ///< web diameter when anchors are NULL [m]
    spn_web_materials materials; ///< default: the silk preset (another preset: set `strains` to its own)
    int radii;                 ///< number of radii
    double hub_radius;         ///< [m]
    double free_zone;          ///< width of the free zone between hub and capture spiral [m]
    double mesh_inner;         ///< capture-spiral gap near the free zone [m]
    double mesh_outer;         ///< capture-spiral gap at the frame [m]
    double hub_offset;         ///< hub above the centre, fraction of the frame's height
    double contraction;        ///< frame contraction m (Japanese thesis), [0, 0.6]
    double margin;             ///< gap between the last spiral turn and the frame [m]
    bool aux_spiral;           ///< lay an auxiliary spiral, then remove it as the capture spiral goes in
    bool keep_aux_spiral;      ///< keep it in the result (for inspection)
    double open_sector;        ///< angular width of Zygiella's open sector [rad], 0: none
    double open_sector_angle;  ///< its direction from the hub [rad, from +x], default upper left
    bool stabilimentum;        ///< Argiope's zig-zag band above and below the hub
    double jitter;             ///< relative natural variation of angles and gaps, default 0.08
    double segment;            ///< division into springs, as geometric
    spn_web_strains strains;   ///< as geometric; default: silk's
    bool form_find;            ///< as geometric; default true
    uint64_t seed;
    spn_world_def world;
} spn_species_def;

/// The preset for `species` (with seed 1; set `seed` for another individual).
SPN_API spn_species_def spn_species_def_preset(spn_species species);
SPN_API spn_status spn_web_build_species(const spn_species_def *def, spn_world **out);

/// Check anchors for a builder: at least 3, finite, distinct, not collinear,
/// and in an order whose frame polygon does not cross itself. The message
/// names the anchor by index.
SPN_API spn_status spn_web_check_anchors(const spn_vec3 *anchors, int count);

/// Air drag [1/s] spn_web_settle and spn_inscribe's settles give a web while
/// it comes to rest (spn_settle_def.drag): about critical for a web's slow
/// modes, a few Hz. It changes the path to rest, not the rest state.
#define SPN_SETTLE_DRAG 20.0

/// Settle a freshly built web, to thresholds relative to the web's own weight
/// and thread tensions. First the static equilibrium (spn_world_equilibrium:
/// springs and gravity balanced, velocities 0; no time passes), when nothing
/// else acts on the web (no force, air or collide callback, no collider, no
/// Provot limit) and its rest state breaks no spring. Where that solve does
/// not reach the threshold (at most 50 Newton steps, fewer when 10 of them
/// do not halve the residual), the web steps in time from as it was built:
/// a time step the world's integrator can take (explicit ones: a fraction of
/// the stiffest spring's period; implicit: 5 ms), extra air drag while
/// settling (restored afterwards; it changes how fast the web comes to rest,
/// not where). At most `max_time` simulated seconds.
SPN_API spn_status spn_web_settle(spn_world *w, double max_time, spn_settle_report *report);

/// The static equilibrium of `w` solved for directly (spn_world_equilibrium),
/// to a largest net force of `target` N on any free particle (and at most a
/// hundredth of the lightest free particle's weight: the solve sets every
/// velocity to 0, so only the residual tells a particle that would still
/// fall), in at most
/// `max_steps` Newton steps, in rounds of 10 and given up sooner when a round
/// does not halve the residual (where it converges it does; where it crawls,
/// on light particles between slack threads, more steps seldom help): what
/// spn_web_settle does first (50 steps), for a web that was edited rather
/// than built (spn_inscribe's settle after editing).
/// *solved when it reached `target` and the rest state breaks no spring:
/// the web is then at rest, velocities 0, and `report` says so as
/// spn_web_settle's does (reason SPN_SETTLE_CONVERGED, no time or steps,
/// the residual and energy). Otherwise (it fell short, or something besides
/// springs, gravity and damping acts on the web: a force, air or collide
/// callback, a collider, a Provot limit) the web is left as it was and the
/// reason is SPN_SETTLE_TIMEOUT. report->newton_steps: the steps taken
/// either way. Errors: out of memory.
SPN_API spn_status spn_web_solve_rest(spn_world *w, double target, int max_steps, bool *solved,
                                      spn_settle_report *report);

/// The web as it stood when `fraction` (0..1) of its springs, in construction
/// order, had been laid: a new world holding those springs. The auxiliary
/// spiral is taken away as the capture spiral passes it (the spider eats it
/// as it goes), so a web built with keep_aux_spiral animates as a spider
/// builds. For building animations (`spinneret build --frames`).
SPN_API spn_status spn_web_construction_state(const spn_world *w, double fraction, spn_world **out);

/* ==== Web measures ======================================================= */

/// What `spinneret info` reports for a web. Lengths in metres, areas m^2.
typedef struct spn_web_measures {
    int radii;                  ///< radius threads meeting the hub
    int turns_above;            ///< capture-spiral crossings of the vertical above the hub
    int turns_below;            ///< ... and below it
    double mesh_inner;          ///< mean gap between spiral turns, inner half of the capture zone
    double mesh_outer;          ///< ... outer half
    spn_vec3 hub;               ///< hub centre
    double asymmetry;           ///< hub-to-top / hub-to-bottom of the capture area (1: centred)
    double capture_area;        ///< area inside the outermost capture spiral minus the hole inside
    double free_zone;           ///< gap between hub and innermost capture turn
    double silk_length[SPN_WEB_KINDS]; ///< current length of each thread kind
    double total_length;
    double total_mass;          ///< kg
    double max_residual;        ///< largest residual force on a free particle [N]
    uint32_t springs_per_kind[SPN_WEB_KINDS];
} spn_web_measures;

/// Measure a web (threads read from their tags). Webs with no radius or
/// capture threads get zeros for those measures.
SPN_API spn_status spn_web_measure(spn_world *w, spn_web_measures *out);
/// Write the measures as a JSON object (no trailing newline) or as text lines.
SPN_API spn_status spn_web_measures_write(const spn_web_measures *m, bool json, spn_sink *sink);

#ifdef __cplusplus
}
#endif
#endif

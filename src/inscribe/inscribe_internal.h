/* Shared between the files of the inscription part: the target raster's
 * layout, the web raster (the thesis' "source image"), dilation and the
 * 5-pixel band sums that scores are made of, and the graph edits. */
#ifndef SPN_INSCRIBE_INTERNAL_H
#define SPN_INSCRIBE_INTERNAL_H

#include "spinneret/inscribe.h"
#include "spinneret/web.h"

struct spn_target {
    int width, height;
    double x0, y0;   /* world coordinates of the top-left corner */
    double scale;    /* pixels per metre */
    float *ink;      /* width * height, 0..1 */
};

/* Half-width of the segment neighbourhood: 5 pixels wide (thesis ch. 6). */
#define SPN__BAND_HALF 2.5
/* The thesis' 7x7 structuring element: radius 3. */
#define SPN__DILATE_RADIUS 3

/* Where a box of half-size (aw, ah) [any unit] fits best in the capture
 * spiral: its centre and the largest scale [m per unit] that keeps it inside. */
spn_status spn__fit_box(const spn_world *w, double aw, double ah, spn_vec3 *centre, double *scale);
/* A raster of the same frame as `t`, zero ink. */
float *spn__raster_alloc(const spn_target *t);
/* The web drawn as 1-pixel threads, ink 1 on 0 (the source image). */
spn_status spn__raster_web(const spn_world *w, const spn_target *t, float *ink);
/* In-place grey dilation with a square (2r+1) x (2r+1) structuring element. */
spn_status spn__dilate(float *ink, int width, int height, int r);
/* Sum of ink over the band of half-width SPN__BAND_HALF px along a -> b; *count gets the pixels. */
double spn__band_sum(const spn_target *t, const float *ink, spn_vec3 a, spn_vec3 b, double *count);
/* Thesis score (fig 6.9) from the summed source and target ink of a band. */
int spn__score(double source_sum, double target_sum);

/* Adjacency of intact springs (CSR). */
typedef struct spn__graph {
    uint32_t np, ns;
    uint32_t *start; /* np + 1 */
    uint32_t *edge;  /* spring ids */
} spn__graph;
spn_status spn__graph_build(const spn_world *w, const bool *skip, spn__graph *g);
void spn__graph_free(spn__graph *g);
uint32_t spn__other_end(const spn_world *w, uint32_t s, uint32_t p);

/* Thread material estimated from the capture springs of a web. */
typedef struct spn__material {
    double ea;        /* axial stiffness k * rest [N] */
    double density;   /* kg/m */
    double prestrain; /* length / rest - 1 */
    double damping;   /* kd / (2 sqrt(k m_seg)) */
    bool tension_only;
} spn__material;
spn__material spn__capture_material(const spn_world *w);
/* Add a thread of `tag` from a to b laid at its current length with the material's prestrain. */
spn_status spn__add_thread(spn_world *w, const spn__material *m, uint32_t a, uint32_t b, uint32_t tag);

/* Take out dangling threads (free particles with one thread), threads not
 * connected to a fixed particle, and particles left with no thread, all in
 * place (spn_world_remove_particles: ids change, every world setting stays).
 * `remove` (spring_count entries, may be NULL) marks springs to take out
 * first. Counts go to *pruned and *particles_removed. */
spn_status spn__clean(spn_world *w, const bool *remove, uint32_t *pruned, uint32_t *particles_removed);

/* Fill emphasis (fill.c): random attachments inside the target. */
spn_status spn__fill(spn_world *w, const spn_target *t, const spn__material *m, double spacing, uint64_t seed,
                     uint32_t *added, uint32_t *split);

#endif

/* Thread styles: width, grey factor, drawing rank and legend colour per thread
 * kind, and the colour scale for tension and strain.
 *
 * Widths are in pixels on a 1200 px canvas (they scale with the canvas). The
 * structural threads (anchor, frame, bridge) are heavier than the radii, and
 * the capture spiral is the finest, as in real orb webs where dragline is
 * several times thicker than capture silk (Mehla 2005, sec. 5.3.8 grey
 * shades: strands differ in shade; the factors below keep them within ~15%). */
#include "render_internal.h"
#include "spinneret/web.h"

#include <math.h>

typedef struct kind_style {
    uint32_t tag;
    double width, shade;
    int rank;
    double rgb[3];   /* colour_by kind */
} kind_style;

static const kind_style styles[] = {
    {SPN_THREAD_GENERIC, 1.3, 1.00, 5, {0.80, 0.80, 0.80}},
    {SPN_THREAD_ANCHOR, 2.4, 1.00, 0, {0.95, 0.55, 0.20}},
    {SPN_THREAD_BRIDGE, 2.2, 1.00, 0, {0.95, 0.80, 0.25}},
    {SPN_THREAD_FRAME, 2.0, 1.00, 1, {0.95, 0.35, 0.35}},
    {SPN_THREAD_RADIUS, 1.4, 0.97, 2, {0.35, 0.70, 0.95}},
    {SPN_THREAD_HUB, 1.1, 0.93, 3, {0.70, 0.50, 0.95}},
    {SPN_THREAD_AUX_SPIRAL, 0.8, 0.75, 4, {0.55, 0.55, 0.55}},
    {SPN_THREAD_CAPTURE, 1.0, 0.92, 6, {0.40, 0.90, 0.50}},
    {SPN_THREAD_INSCRIPTION, 1.3, 1.00, 7, {0.98, 0.90, 0.40}},
    {SPN_THREAD_STABILIMENTUM, 3.0, 1.00, 8, {1.00, 1.00, 1.00}},
    {SPN_THREAD_SIGNAL, 1.3, 1.00, 2, {0.30, 0.90, 0.90}},
    {SPN_THREAD_STRETCH, 1.0, 1.00, 5, {0.85, 0.85, 0.85}},
    {SPN_THREAD_BEND, 0.6, 0.60, 4, {0.50, 0.50, 0.70}},
    {SPN_THREAD_VICINITY, 0.6, 0.60, 4, {0.70, 0.50, 0.50}},
    {SPN_THREAD_SHOT, 1.6, 1.00, 2, {0.90, 0.90, 1.00}},
};

static const kind_style *find(uint32_t tag)
{
    for (size_t i = 0; i < sizeof styles / sizeof styles[0]; i++)
        if (styles[i].tag == tag) return &styles[i];
    return &styles[0];
}

double spn_thread_kind_width(uint32_t tag) { return find(tag)->width; }
double spn_thread_kind_shade(uint32_t tag) { return find(tag)->shade; }
int spn__kind_rank(uint32_t tag) { return find(tag)->rank; }

void spn__kind_colour(uint32_t tag, double rgb[3])
{
    const kind_style *k = find(tag);
    if (k == &styles[0] && tag != SPN_THREAD_GENERIC) {
        /* An unknown tag still gets a colour of its own, from a golden-ratio hue walk. */
        double h = fmod(tag * 0.618033988749895, 1.0) * 6.0;
        double f = h - floor(h), q = 1 - f;
        double c[6][3] = {{1, f, 0}, {q, 1, 0}, {0, 1, f}, {0, q, 1}, {f, 0, 1}, {1, 0, q}};
        int i = (int)h % 6;
        for (int j = 0; j < 3; j++) rgb[j] = 0.35 + 0.6 * c[i][j];
        return;
    }
    for (int j = 0; j < 3; j++) rgb[j] = k->rgb[j];
}

/* A blue - cyan - green - yellow - red scale, every stop bright enough to read
 * as a thin line on a dark background. */
void spn__scale_colour(double t, double rgb[3])
{
    static const double stops[5][3] = {
        {0.18, 0.30, 0.85}, {0.10, 0.70, 0.85}, {0.45, 0.85, 0.35}, {0.98, 0.80, 0.20}, {0.95, 0.25, 0.15}};
    if (!(t > 0)) t = 0;
    if (t > 1) t = 1;
    double x = t * 4;
    int i = (int)x;
    if (i > 3) i = 3;
    double f = x - i;
    for (int j = 0; j < 3; j++) rgb[j] = stops[i][j] * (1 - f) + stops[i + 1][j] * f;
}

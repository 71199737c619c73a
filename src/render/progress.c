/* A progress bar on stderr for the animating commands: one line redrawn in
 * place with a carriage return, shown only when stderr is a terminal (so logs
 * and pipes stay clean) and not asked to be quiet. Redrawn only when the
 * shown percentage changes, so a million tiny steps cost a hundred writes. */
#include "spinneret/render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

struct spn_progress {
    char label[48];
    uint64_t total;
    int shown;   /* last percentage drawn, -1 before the first */
};

spn_progress *spn_progress_begin(const char *label, uint64_t total, bool quiet)
{
    if (quiet || !isatty(fileno(stderr))) return NULL;
    spn_progress *p = calloc(1, sizeof *p);
    if (!p) return NULL;
    snprintf(p->label, sizeof p->label, "%s", label ? label : "");
    p->total = total ? total : 1;
    p->shown = -1;
    spn_progress_update(p, 0);
    return p;
}

void spn_progress_update(spn_progress *p, uint64_t done)
{
    if (!p) return;
    if (done > p->total) done = p->total;
    int pct = (int)(done * 100 / p->total);
    if (pct == p->shown) return;
    p->shown = pct;
    char bar[31];
    int fill = pct * 30 / 100;
    memset(bar, '#', (size_t)fill);
    memset(bar + fill, '.', (size_t)(30 - fill));
    bar[30] = '\0';
    fprintf(stderr, "\r%s [%s] %3d%% (%llu/%llu)", p->label, bar, pct, (unsigned long long)done,
            (unsigned long long)p->total);
    fflush(stderr);
}

void spn_progress_end(spn_progress *p)
{
    if (!p) return;
    spn_progress_update(p, p->total);
    fputc('\n', stderr);
    fflush(stderr);
    free(p);
}

/* Fuzz harness: the prey parser behind `animate --impact
 * "X,Y,Z;VX,VY,VZ;MASS;RADIUS"` (spn_prey_parse). Accepted prey must be
 * finite with a positive mass and radius; a refusal must say why. */
#include <spinneret/spinneret.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096) return -1;
    char *text = malloc(size + 1);
    memcpy(text, data, size);
    text[size] = '\0';
    spn_prey_def p;
    if (spn_prey_parse(text, &p) == SPN_OK) {
        if (!spn_v3_finite(p.position) || !spn_v3_finite(p.velocity) || !(p.mass > 0) || !isfinite(p.mass) ||
            !(p.radius > 0) || !isfinite(p.radius))
            abort();
    } else if (!spn_last_error()[0]) {
        abort();
    }
    free(text);
    return 0;
}

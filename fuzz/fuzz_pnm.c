/* Fuzz harness: the PBM/PGM reader behind `inscribe --image` (spn_pnm_read,
 * P1, P2, P4, P5). It reads a path, so each input is written to a private
 * temporary file first. An accepted image has a positive size and its pixels;
 * a refusal says why and leaves no image. (PNG goes through cairo's libpng,
 * not ours.) */
#define _POSIX_C_SOURCE 200809L
#include <spinneret/spinneret.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static char path[64];
    if (!path[0]) snprintf(path, sizeof path, "/tmp/spn-fuzz-pnm-%ld.pgm", (long)getpid());
    FILE *fp = fopen(path, "wb");
    if (!fp) abort();
    fwrite(data, 1, size, fp);
    fclose(fp);
    spn_grey_image img;
    memset(&img, 0xA5, sizeof img);
    if (spn_pnm_read(path, &img) == SPN_OK) {
        if (img.width < 1 || img.height < 1 || !img.pixels) abort();
        volatile uint8_t sum = 0;
        for (size_t i = 0; i < (size_t)img.width * (size_t)img.height; i++) sum += img.pixels[i]; /* all readable */
        spn_grey_image_free(&img);
    } else if (!spn_last_error()[0]) {
        abort();
    }
    unlink(path);
    return 0;
}

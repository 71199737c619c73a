/* pngprobe: measures a PNG for the shell tests, so pictures are checked by
 * where ink falls rather than by bytes.
 *   pngprobe FILE                  prints "W H"
 *   pngprobe FILE X Y W H [T]      over the rectangle, prints
 *                                  "mean=M min=A max=B dark=D bright=L"
 * M, A, B are luminances 0..255 (alpha composited over black); D and L are the
 * fractions of pixels below 255-T and above T (T default 64). */
#include <cairo.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    if (argc != 2 && argc != 6 && argc != 7) {
        fprintf(stderr, "usage: pngprobe FILE [X Y W H [T]]\n");
        return 2;
    }
    cairo_surface_t *s = cairo_image_surface_create_from_png(argv[1]);
    if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS) {
        fprintf(stderr, "pngprobe: %s: cannot read PNG\n", argv[1]);
        return 1;
    }
    int w = cairo_image_surface_get_width(s), h = cairo_image_surface_get_height(s);
    if (argc == 2) {
        printf("%d %d\n", w, h);
        return 0;
    }
    int x0 = atoi(argv[2]), y0 = atoi(argv[3]), rw = atoi(argv[4]), rh = atoi(argv[5]);
    int t = argc == 7 ? atoi(argv[6]) : 64;
    if (x0 < 0 || y0 < 0 || rw < 1 || rh < 1 || x0 + rw > w || y0 + rh > h) {
        fprintf(stderr, "pngprobe: rectangle outside the %dx%d image\n", w, h);
        return 2;
    }
    cairo_format_t fmt = cairo_image_surface_get_format(s);
    const unsigned char *data = cairo_image_surface_get_data(s);
    int stride = cairo_image_surface_get_stride(s);
    double sum = 0;
    int lo = 255, hi = 0;
    long dark = 0, bright = 0;
    for (int y = y0; y < y0 + rh; y++)
        for (int x = x0; x < x0 + rw; x++) {
            unsigned px = *(const unsigned *)(data + (size_t)y * stride + 4 * (size_t)x);
            unsigned r = px >> 16 & 255, g = px >> 8 & 255, b = px & 255;
            if (fmt == CAIRO_FORMAT_A8) r = g = b = data[(size_t)y * stride + (size_t)x];
            int l = (int)(0.2126 * r + 0.7152 * g + 0.0722 * b + 0.5);
            sum += l;
            lo = l < lo ? l : lo;
            hi = l > hi ? l : hi;
            dark += l < 255 - t;
            bright += l > t;
        }
    double n = (double)rw * rh;
    printf("mean=%.2f min=%d max=%d dark=%.4f bright=%.4f\n", sum / n, lo, hi, dark / n, bright / n);
    cairo_surface_destroy(s);
    return 0;
}

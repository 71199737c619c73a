/* The shot's path and noise (Zimmerman, source 004: "Simple Physics" and
 * "Custom Noise").
 *
 * Path: the ballistic arc under constant gravity through origin and target at
 * the smallest elevation angle. With x the horizontal distance (normal to
 * gravity), y the rise along -g, G = |g| and v the speed, the elevation obeys
 *   G x^2 tan^2(th) - 2 v^2 x tan(th) + (G x^2 + 2 y v^2) = 0,
 * whose smaller root is tan(th) = (v^2 - sqrt(D)) / (G x),
 *   D = v^4 - G (G x^2 + 2 y v^2)   (D < 0: out of reach).
 * We use the conjugate form tan(th) = (G x^2 + 2 y v^2) / (x (v^2 + sqrt(D))),
 * free of cancellation, and take th = atan2 of its numerator and denominator so
 * a vertical shot (x = 0) needs no special case. Flight time
 * T = x / (v cos th) = hypot(num, den) / (v (v^2 + sqrt(D))), again without x.
 *
 * Noise: n random values in [0, 1] spread linearly over the samples, then three
 * rounds of: cumulative trapezoidal integral (starts at 0), tilt by the line
 * through its end (so it ends at 0), scale by the largest magnitude (so it
 * spans [-1, 1]). Integration is what smooths; three rounds make the second
 * derivative continuous. The source scales before it tilts; we tilt first so
 * that both promises (ends at 0, range [-1, 1]) hold at once. */
#include "shoot_internal.h"

#include <math.h>

/* Split d = target - origin into the horizontal direction, horizontal
 * distance x and rise y, with up = -g / |g|. Gravity zero: up is +y. */
static void split(spn_vec3 origin, spn_vec3 target, spn_vec3 gravity, spn_vec3 *up, spn_vec3 *hdir, double *x,
                  double *y)
{
    double g = spn_v3_len(gravity);
    *up = g > 0 ? spn_v3_scale(gravity, -1.0 / g) : spn_v3(0, 1, 0);
    spn_vec3 d = spn_v3_sub(target, origin);
    *y = spn_v3_dot(d, *up);
    spn_vec3 h = spn_v3_sub(d, spn_v3_scale(*up, *y));
    *x = spn_v3_len(h);
    *hdir = spn_v3_norm(h);
}

double spn_ballistic_min_speed(spn_vec3 origin, spn_vec3 target, spn_vec3 gravity)
{
    spn_vec3 up, hdir;
    double x, y, g = spn_v3_len(gravity);
    split(origin, target, gravity, &up, &hdir, &x, &y);
    return sqrt(g * (y + hypot(x, y)));
}

static spn_status check_inputs(spn_vec3 origin, spn_vec3 target, spn_vec3 gravity, double speed)
{
    if (!spn_v3_finite(origin)) return spn_error(SPN_ERR_INVALID, "shot: origin must be finite");
    if (!spn_v3_finite(target)) return spn_error(SPN_ERR_INVALID, "shot: target must be finite");
    if (!spn_v3_finite(gravity)) return spn_error(SPN_ERR_INVALID, "shot: gravity must be finite");
    if (!(speed > 0) || !isfinite(speed)) return spn_error(SPN_ERR_INVALID, "shot: speed must be positive, got %g", speed);
    if (spn_v3_len(spn_v3_sub(target, origin)) < 1e-6)
        return spn_error(SPN_ERR_INVALID, "shot: target must be at least 1 um from origin");
    return SPN_OK;
}

spn_status spn_ballistic_solve(spn_vec3 origin, spn_vec3 target, spn_vec3 gravity, double speed, bool auto_speed,
                               spn_ballistic *out)
{
    spn_status st = check_inputs(origin, target, gravity, speed);
    if (st != SPN_OK) return st;
    spn_vec3 up, hdir;
    double x, y, g = spn_v3_len(gravity);
    split(origin, target, gravity, &up, &hdir, &x, &y);
    double vmin = sqrt(g * (y + hypot(x, y)));
    double v = speed, v2 = v * v;
    double disc = v2 * v2 - g * (g * x * x + 2 * y * v2);
    if (disc < 0 && !auto_speed)
        return spn_error(SPN_ERR_INVALID,
                         "shot: target (%g, %g, %g) is out of reach at speed %g m/s: it needs at least %.6g m/s "
                         "(raise the speed or use auto speed)",
                         target.x, target.y, target.z, speed, vmin);
    if (disc < 0) {
        /* At the least speed the two roots meet: D = 0 in exact arithmetic. */
        v = vmin;
        v2 = v * v;
        disc = 0;
    }
    double sq = sqrt(disc);
    double num = g * x * x + 2 * y * v2, den = x * (v2 + sq);
    double h = hypot(num, den);
    double c = den / h, s = num / h;
    out->origin = origin;
    out->target = target;
    out->gravity = gravity;
    out->speed = v;
    out->min_speed = vmin;
    out->elevation = atan2(num, den);
    out->velocity = spn_v3_add(spn_v3_scale(hdir, v * c), spn_v3_scale(up, v * s));
    out->flight_time = h / (v * (v2 + sq));
    return SPN_OK;
}

spn_vec3 spn_ballistic_position(const spn_ballistic *b, double t)
{
    return spn_v3_add(b->origin, spn_v3_add(spn_v3_scale(b->velocity, t), spn_v3_scale(b->gravity, 0.5 * t * t)));
}

spn_vec3 spn_ballistic_velocity(const spn_ballistic *b, double t)
{
    return spn_v3_add(b->velocity, spn_v3_scale(b->gravity, t));
}

/* One round: integrate (trapezoids, unit total width), tilt, scale. */
static void noise_round(double *y, int n)
{
    double h = 1.0 / (n - 1), acc = 0, prev = y[0];
    y[0] = 0;
    for (int i = 1; i < n; i++) {
        double cur = y[i];
        acc += 0.5 * (prev + cur) * h;
        prev = cur;
        y[i] = acc;
    }
    double end = y[n - 1], big = 0;
    for (int i = 0; i < n; i++) {
        y[i] -= end * (double)i / (n - 1);
        if (fabs(y[i]) > big) big = fabs(y[i]);
    }
    y[n - 1] = 0; /* exactly, whatever the rounding of end * 1 */
    if (big > 0)
        for (int i = 0; i < n; i++) y[i] /= big;
}

spn_status spn_smooth_noise(spn_rng *rng, int points, double *out, int samples)
{
    if (points < 2 || points > 256) return spn_error(SPN_ERR_INVALID, "noise: points must be in [2, 256], got %d", points);
    if (samples < points || samples > (1 << 20))
        return spn_error(SPN_ERR_INVALID, "noise: samples must be in [%d, %d], got %d", points, 1 << 20, samples);
    double r[256];
    for (int j = 0; j < points; j++) r[j] = spn_rng_uniform(rng);
    for (int i = 0; i < samples; i++) {
        double u = (double)i * (points - 1) / (samples - 1);
        int j = (int)u;
        if (j >= points - 1) j = points - 2;
        double f = u - j;
        out[i] = r[j] + f * (r[j + 1] - r[j]);
    }
    for (int round = 0; round < 3; round++) noise_round(out, samples);
    return SPN_OK;
}

double spn__noise_at(const double *curve, int samples, double u)
{
    if (!(u > 0)) return curve[0];
    if (u >= 1) return curve[samples - 1];
    double p = u * (samples - 1);
    int i = (int)p;
    if (i >= samples - 1) i = samples - 2;
    double f = p - i;
    return curve[i] + f * (curve[i + 1] - curve[i]);
}

void spn__path_frame(const spn_ballistic *b, double t, spn_vec3 *side, spn_vec3 *lift)
{
    spn_vec3 fwd = spn_v3_norm(spn_ballistic_velocity(b, t));
    double g = spn_v3_len(b->gravity);
    spn_vec3 up = g > 0 ? spn_v3_scale(b->gravity, -1.0 / g) : spn_v3(0, 1, 0);
    spn_vec3 s = spn_v3_cross(fwd, up);
    if (spn_v3_len(s) < 1e-9) {
        /* Travelling along gravity: any side will do; take one fixed in space. */
        spn_vec3 ref = fabs(up.x) < 0.9 ? spn_v3(1, 0, 0) : spn_v3(0, 0, 1);
        s = spn_v3_cross(fwd, ref);
    }
    *side = spn_v3_norm(s);
    *lift = spn_v3_cross(*side, fwd);
}

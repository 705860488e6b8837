/*
 * A hand-written C LuGre step in double precision, the reference for the
 * host comparison (`cargo bench -p friction-bench-c`). Same algorithm as
 * friction-core's `LuGre::step` (src/models/lugre/variable_step.rs, `advance`): Stribeck
 * curve with exponent 2, dz/dt = v - a z with a = sigma0 |v| / g(v) solved
 * exactly for the held v (exponential relaxation, expm1 for small a h), z
 * clamped to +-Fs/sigma0, force at the end of the step with the damping term
 * held at zero while z sits on its bound. Written as a C programmer would:
 * the caller guarantees finite v and h >= 0, so there are no input checks.
 */
#include <math.h>

#include "lugre.h"

static double sat(double x, double a) {
    return x > a ? a : (x < -a ? -a : x);
}

double lugre_c_step(const struct lugre_c *m, double *state, double v, double h) {
    double p = v * m->inv_vs;
    double g = m->fc + m->fs_minus_fc * exp(-(p * p));
    double r = g / m->sigma0;
    double speed = fabs(v);
    double z = *state;
    if (h > 0.0) {
        double a = speed / r;
        double x = a * h;
        if (x > 1.0) {
            double z_eq = sat(v / speed * r, 2.0 * m->z_max);
            z = z_eq + (z - z_eq) * exp(-x);
        } else if (x > 0.0) {
            z = z + (v - a * z) * (-expm1(-x) / a);
        } else {
            z = z + v * h;
        }
        z = sat(z, m->z_max);
        *state = z;
    }
    double dz = v - speed * (z / r);
    if (fabs(z) >= m->z_max && dz * z > 0.0) {
        dz = 0.0;
    }
    double sigma1 = m->inv_vd_sq > 0.0 ? m->sigma1 * exp(-(v * v * m->inv_vd_sq)) : m->sigma1;
    return m->sigma0 * z + m->sigma2 * v + sigma1 * dz;
}

/*
 * The minimal step issue 19 sizes the host against: implicit (backward)
 * Euler with one exp (the Stribeck curve) and one division,
 * z+ = (z + v h) / (1 + sigma0 |v| h / g), no clamp, the force at the end of
 * the step. First order in h (not the exact step above, which is why the
 * core does not use it); measured for its instruction count only.
 */
double lugre_c_ie_step(const struct lugre_c *m, double *state, double v, double h) {
    double p = v * m->inv_vs;
    double g = m->fc + m->fs_minus_fc * exp(-(p * p));
    double a = m->sigma0 * fabs(v) / g;
    double z = (*state + v * h) / (1.0 + a * h);
    *state = z;
    double sigma1 = m->inv_vd_sq > 0.0 ? m->sigma1 * exp(-(v * v * m->inv_vd_sq)) : m->sigma1;
    return m->sigma0 * z + m->sigma2 * v + sigma1 * (v - a * z);
}

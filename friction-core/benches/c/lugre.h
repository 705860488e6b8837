/* The C LuGre step of the host comparison: parameters as built by
 * friction-core (derived values precomputed). */
#ifndef LUGRE_C_H
#define LUGRE_C_H

struct lugre_c {
    double fc;
    double fs_minus_fc;
    double inv_vs;
    double sigma0;
    double sigma1;
    double sigma2;
    double inv_vd_sq; /* 0: constant sigma1 */
    double z_max;     /* Fs / sigma0 */
};

double lugre_c_step(const struct lugre_c *m, double *state, double v, double h);
double lugre_c_ie_step(const struct lugre_c *m, double *state, double v, double h);

#endif

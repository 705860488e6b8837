/*
 * simulate.c: the LuGre model of Canudas de Wit et al. (1995, Table I;
 * params/canudas1995.toml) through the C ABI, over a velocity signal read
 * as CSV (`t,v` header, then rows) from stdin; writes `t,v,f` to stdout.
 * Row k steps the model from t[k-1] to t[k] with v[k] held; row 0 is the
 * force at rest, as `friction simulate` does.
 *
 *   cc -std=c99 -Iinclude examples/simulate.c target/release/libfriction_ffi.a -lpthread -ldl -lm
 *   ./a.out < input.csv > output.csv
 */
#include <stdio.h>
#include <stdlib.h>

#include "friction.h"

int main(void) {
    const friction_lugre_params params = {
        {1.0, 1.5, 1e-3, 2.0},  /* curve: fc (N), fs (N), vs (m/s), exponent */
        1e5,                    /* sigma0 (N/m) */
        316.22776601683794,     /* sigma1 (N s/m), sqrt(1e5) */
        0.4,                    /* sigma2 (N s/m) */
        0.0,                    /* vd: 0, constant sigma1 */
    };
    friction_model_f64 model;
    friction_error error;
    char header[256];
    double t, v, t_prev = 0.0, f;
    long row = 0;

    /* h = 0: the variable-step form, stepped with each row's own period */
    if (friction_lugre_init_f64(&model, &params, 0.0, &error) != FRICTION_OK) {
        fprintf(stderr, "parameter `%s`: %s\n", (const char *)error.parameter,
                friction_status_name(error.status));
        return 2;
    }
    if (!fgets(header, sizeof header, stdin)) {
        fprintf(stderr, "no header line (t,v)\n");
        return 2;
    }
    printf("t,v,f\n");
    while (scanf("%lf,%lf", &t, &v) == 2) {
        double h = row == 0 ? 0.0 : t - t_prev;
        friction_status status = friction_model_step_f64(&model, v, h, &f);
        if (status != FRICTION_OK) {
            fprintf(stderr, "row %ld: %s\n", row + 2, friction_status_name(status));
            return 1;
        }
        printf("%.17g,%.17g,%.17g\n", t, v, f);
        t_prev = t;
        row++;
    }
    return row > 0 ? 0 : 2;
}

/*
 * main.c: a compensated servo axis in C on a Cortex-M4F through the
 * friction library's C ABI (QEMU mps2-an386), in two parts.
 *
 * 1. The loop: a 1 kHz servo with the LuGre observer (Olsson et al. 1998,
 *    the rotary servo's set; the firmware example's gains) tracks a sine on
 *    a simulated inertia whose friction is the same LuGre model stepped at
 *    10 kHz. The run fails (exit 1) unless the observer cuts the RMS
 *    tracking error at least tenfold against the same loop without it, and
 *    so does the per-parameter adaptive observer under its supervisor
 *    started from friction levels 1.5x the plant's.
 * 2. The cost of `friction_servo_tick_f32` in instructions (SysTick under
 *    `-icount shift=0`), on the cost benchmark's inputs (the sweep and the
 *    stress sequence of friction-firmware-example/src/bin/cost.rs), printed
 *    as `cost-detail` lines for friction-firmware-example/cost.sh.
 */
#include <stdint.h>

#include "board.h"
#include "friction.h"

/* Olsson et al. 1998, Table 2 (LuGre, rotary DC servo) */
static const friction_lugre_params OLSSON = {
    {0.28, 0.33, 0.01, 2.0}, /* fc, fs (N m), vs (rad/s), exponent */
    260.0,                   /* sigma0 (N m/rad) */
    0.6,                     /* sigma1 (N m s/rad) */
    0.0176,                  /* sigma2 (N m s/rad) */
    0.0,                     /* vd: none */
};

#define H 1e-3          /* servo period (s) */
#define INERTIA 0.0023  /* kg m^2 */
#define GAIN 200.0      /* observer gain (1/s) */
#define PLANT_STEPS 10  /* plant sub-steps per servo period */

static friction_servo_params servo_params(void) {
    const double w = 2.0 * 3.14159265358979323846 * 10.0; /* 10 Hz loop */
    friction_servo_params p = {H, INERTIA * w * w, 0.0, 2.0 * INERTIA * w, INERTIA, 1.0, 5.0};
    return p;
}

/* ---- small helpers: no libc ---- */

static void put_int(int64_t v) {
    char buf[24];
    int i = 23;
    int neg = v < 0;
    uint64_t u = neg ? (uint64_t)(-v) : (uint64_t)v;
    buf[i] = 0;
    do {
        buf[--i] = (char)('0' + u % 10);
        u /= 10;
    } while (u);
    if (neg) buf[--i] = '-';
    board_puts(&buf[i]);
}

/* x with `d` decimals (x >= 0) */
static void put_fixed(float x, int d) {
    int64_t scale = 1, v;
    int i;
    for (i = 0; i < d; i++) scale *= 10;
    v = (int64_t)(x * (float)scale + 0.5f);
    put_int(v / scale);
    if (d > 0) {
        char frac[12];
        int64_t f = v % scale;
        for (i = d - 1; i >= 0; i--) {
            frac[i] = (char)('0' + f % 10);
            f /= 10;
        }
        frac[d] = 0;
        board_puts(".");
        board_puts(frac);
    }
}

static int check(friction_status s, const char *what) {
    if (s != FRICTION_OK) {
        board_puts(what);
        board_puts(": ");
        board_puts(friction_status_name(s));
        board_puts("\n");
        return 1;
    }
    return 0;
}

/* sin(x) for |x| <= 4 pi: range reduction and a 9th-order polynomial
   (to about 1e-6, plenty for test signals) */
static float sine(float x) {
    const float pi = 3.14159265f;
    float x2;
    while (x > pi) x -= 2.0f * pi;
    while (x < -pi) x += 2.0f * pi;
    if (x > 0.5f * pi) x = pi - x;
    if (x < -0.5f * pi) x = -pi - x;
    x2 = x * x;
    return x * (1.0f - x2 / 6.0f * (1.0f - x2 / 20.0f * (1.0f - x2 / 42.0f * (1.0f - x2 / 72.0f))));
}

static float sqrt_f(float x) {
    float r = x > 1.0f ? x : 1.0f;
    int i;
    if (x <= 0.0f) return 0.0f;
    for (i = 0; i < 40; i++) r = 0.5f * (r + x / r);
    return r;
}

/* ---- 1. the compensated loop ---- */

/* RMS tracking error (rad) of 3 s tracking 0.05 sin(2 pi 0.5 t) rad with
   `servo` (built by the caller) */
static int track(friction_servo_f32 *servo, float *rms, float *peak) {
    friction_model_f32 plant;
    friction_tick_f32 out = {0.0f, 0.0f};
    friction_error err;
    float x = 0.0f, v = 0.0f, sum = 0.0f, worst = 0.0f;
    const float w = 2.0f * 3.14159265f * 0.5f, a = 0.05f, dh = (float)(H / PLANT_STEPS);
    int k, j, n = 3000;

    if (check(friction_lugre_init_f32(&plant, &OLSSON, 0.0, &err), "plant")) return 1;
    for (k = 0; k < n; k++) {
        float t = (float)k * (float)H;
        friction_setpoint_f32 r;
        float e;
        r.x = a * sine(w * t);
        r.v = a * w * sine(w * t + 0.5f * 3.14159265f);
        r.a = -a * w * w * sine(w * t);
        e = x - r.x;
        sum += e * e;
        if (e < 0.0f) e = -e;
        if (e > worst) worst = e;
        if (check(friction_servo_tick_f32(servo, x, r, &out), "tick")) return 1;
        for (j = 0; j < PLANT_STEPS; j++) {
            float f;
            if (check(friction_model_step_f32(&plant, v, dh, &f), "plant step")) return 1;
            v += dh * (out.command - f) / (float)INERTIA;
            x += dh * v;
        }
    }
    *rms = sqrt_f(sum / (float)n);
    *peak = worst;
    return 0;
}

/* the servo with the observer (`gain` > 0) or without (`gain` == 0: no model) */
static int observer_servo(friction_servo_f32 *servo, double gain) {
    friction_model_f32 model;
    friction_servo_params p = servo_params();
    friction_error err;
    if (check(friction_lugre_init_f32(&model, &OLSSON, H, &err), "model")) return 1;
    return check(friction_servo_init_f32(servo, &p, gain > 0.0 ? &model : 0, gain, 0, &err),
                 "servo");
}

/* the servo with the per-parameter adaptive observer under its supervisor,
   from a model whose friction levels are 1.5x the plant's (and a static
   fallback with the same wrong Coulomb level) */
static int parameter_servo(friction_servo_f32 *servo) {
    friction_lugre_params wrong = OLSSON;
    friction_parameter_adaptive_params adaptive;
    friction_supervisor_params supervisor;
    friction_coulomb_viscous_params fallback;
    friction_servo_params p = servo_params();
    friction_error err;
    wrong.curve.fc *= 1.5;
    wrong.curve.fs *= 1.5;
    if (check(friction_parameter_adaptive_defaults(&wrong, GAIN, &adaptive), "defaults"))
        return 1;
    adaptive.rate = 16.0;  /* the command line's default rate (1/s) */
    adaptive.speed = 0.16; /* the trajectory's peak speed (rad/s) */
    if (check(friction_supervisor_defaults(&supervisor), "defaults")) return 1;
    supervisor.tolerance = 0.01 * OLSSON.curve.fc;
    fallback.fc = wrong.curve.fc;
    fallback.sigma2 = wrong.sigma2;
    return check(friction_servo_parameter_adaptive_init_f32(servo, &p, &adaptive, &supervisor,
                                                            &fallback, &err),
                 "per-parameter servo");
}

/* ---- 2. the cost of a tick ---- */

#define REPS 64
#define SWEEP_STEPS 1024
static const float STRESS[14] = {1e-4f, 1e-3f, 3e-3f, 0.01f, 0.03f, 0.1f, 0.3f,
                                 1.0f,  3.0f,  10.0f, 50.0f, 1e3f,  1e6f, 1e7f};
static const float PATTERN[6] = {1.0f, -1.0f, 1.0f, 1.0f, -1.0f, -1.0f};

typedef friction_status (*tick_fn)(friction_servo_f32 *, float, friction_setpoint_f32,
                                   friction_tick_f32 *);

/* the baseline: the same call, doing nothing */
__attribute__((noinline)) static friction_status tick_none(friction_servo_f32 *s, float x,
                                                           friction_setpoint_f32 r,
                                                           friction_tick_f32 *out) {
    __asm__ volatile("" : : "r"(s), "r"(out), "r"(&r), "r"(&x) : "memory");
    return FRICTION_OK;
}

static tick_fn volatile tick_real = friction_servo_tick_f32;
static tick_fn volatile tick_empty = tick_none;

static void copy_servo(friction_servo_f32 *d, const friction_servo_f32 *s) {
    int i;
    for (i = 0; i < FRICTION_SERVO_F32_WORDS; i++) d->opaque[i] = s->opaque[i];
}

static uint32_t elapsed(uint32_t start) { return (start - board_systick()) & 0x00FFFFFF; }

/* instructions of one tick from `start`, replayed REPS times, less the empty call */
static float replay(float per_tick, const friction_servo_f32 *start, float x,
                    friction_setpoint_f32 r) {
    static friction_servo_f32 s;
    friction_tick_f32 out;
    uint32_t t0, t, base;
    int i;
    tick_fn f = tick_real, g = tick_empty;
    t0 = board_systick();
    for (i = 0; i < REPS; i++) {
        copy_servo(&s, start);
        f(&s, x, r, &out);
    }
    t = elapsed(t0);
    t0 = board_systick();
    for (i = 0; i < REPS; i++) {
        copy_servo(&s, start);
        g(&s, x, r, &out);
    }
    base = elapsed(t0);
    return ((float)t - (float)base) * per_tick / (float)REPS;
}

static float calibrate(void) {
    uint32_t t0, empty, nops;
    int i;
    t0 = board_systick();
    for (i = 0; i < 16384; i++) __asm__ volatile("" ::: "memory");
    empty = elapsed(t0);
    t0 = board_systick();
    for (i = 0; i < 16384; i++)
        __asm__ volatile(".rept 16\n nop\n .endr" ::: "memory");
    nops = elapsed(t0);
    if (nops <= empty) return 0.0f;
    return (float)(16 * 16384) / (float)(nops - empty);
}

static void sweep(int k, float *x, friction_setpoint_f32 *r) {
    float s = sine((float)(k % 64) * 0.1963f);
    *x = 1e-3f * s;
    r->x = *x + 1e-5f;
    r->v = 0.01f * s;
    r->a = 0.0f;
}

static void stress(int k, float *x, friction_setpoint_f32 *r) {
    float v = STRESS[k / 6] * PATTERN[k % 6];
    *x = 1e-3f * v;
    r->x = 0.0f;
    r->v = v;
    r->a = 0.0f;
}

static int cost(void) {
    static friction_servo_f32 servo, run;
    friction_model_f32 model;
    friction_servo_params p = servo_params();
    friction_setpoint_f32 r;
    friction_tick_f32 out;
    float per_tick, sum = 0.0f, worst = -1.0f, c, x, straight;
    int k, worst_at = 0, worst_stress = 0;
    uint32_t t0, t, base;

    board_systick_start();
    per_tick = calibrate();
    if (per_tick < 1.0f) {
        board_puts("SysTick does not advance with instructions (run QEMU with -icount shift=0)\n");
        return 1;
    }
    per_tick = (float)(int)(per_tick + 0.5f);
    if (check(friction_lugre_init_f32(&model, &OLSSON, H, 0), "model")) return 1;
    if (check(friction_servo_init_f32(&servo, &p, &model, GAIN, 0, 0), "servo")) return 1;
    copy_servo(&run, &servo);
    for (k = 0; k < SWEEP_STEPS; k++) {
        sweep(k, &x, &r);
        c = replay(per_tick, &run, x, r);
        sum += c;
        if (c > worst) {
            worst = c;
            worst_at = k;
        }
        friction_servo_tick_f32(&run, x, r, &out);
    }
    copy_servo(&run, &servo);
    for (k = 0; k < 14 * 6; k++) {
        stress(k, &x, &r);
        c = replay(per_tick, &run, x, r);
        if (c > worst) {
            worst = c;
            worst_at = k;
            worst_stress = 1;
        }
        friction_servo_tick_f32(&run, x, r, &out);
    }
    /* the sweep straight through, no replay */
    copy_servo(&run, &servo);
    t0 = board_systick();
    for (k = 0; k < SWEEP_STEPS; k++) {
        sweep(k, &x, &r);
        tick_real(&run, x, r, &out);
    }
    t = elapsed(t0);
    copy_servo(&run, &servo);
    t0 = board_systick();
    for (k = 0; k < SWEEP_STEPS; k++) {
        sweep(k, &x, &r);
        tick_empty(&run, x, r, &out);
    }
    base = elapsed(t0);
    straight = ((float)t - (float)base) * per_tick / (float)SWEEP_STEPS;

    board_puts("cost servo-lugre-c-abi f32 cortex-m4f ");
    put_fixed(sum / SWEEP_STEPS, 0);
    board_puts("\ncost-worst servo-lugre-c-abi f32 cortex-m4f ");
    put_fixed(worst, 0);
    board_puts("\ncost-detail servo-lugre-c-abi f32 cortex-m4f fixed avg=");
    put_fixed(sum / SWEEP_STEPS, 1);
    board_puts(" worst=");
    put_fixed(worst, 1);
    board_puts(" ratio=");
    put_fixed(worst / (sum / SWEEP_STEPS), 2);
    board_puts(worst_stress ? " worst-at=stress:" : " worst-at=sweep:");
    put_int(worst_at);
    board_puts(" straight-avg=");
    put_fixed(straight, 1);
    board_puts(" model-bytes=");
    put_int((int64_t)sizeof servo);
    board_puts(" state-bytes=0 stack-bytes=- fn=friction_servo_tick_f32\n");
    return 0;
}

int main(void) {
    float rms_none, peak_none, rms_obs, peak_obs, rms_par, peak_par;
    static friction_servo_f32 servo;
    friction_estimates_f32 est;
    friction_supervisor_status status;
    board_puts("friction C ABI on Cortex-M4F: LuGre observer servo at 1 kHz\n");
    if (observer_servo(&servo, 0.0) || track(&servo, &rms_none, &peak_none)) return 1;
    if (observer_servo(&servo, GAIN) || track(&servo, &rms_obs, &peak_obs)) return 1;
    if (parameter_servo(&servo) || track(&servo, &rms_par, &peak_par)) return 1;
    if (check(friction_servo_estimates_f32(&servo, &est), "estimates") ||
        check(friction_servo_supervisor_f32(&servo, &status), "supervisor"))
        return 1;
    board_puts("tracking error RMS / max (mrad): no compensation ");
    put_fixed(rms_none * 1e3f, 3);
    board_puts(" / ");
    put_fixed(peak_none * 1e3f, 3);
    board_puts(", LuGre observer ");
    put_fixed(rms_obs * 1e3f, 3);
    board_puts(" / ");
    put_fixed(peak_obs * 1e3f, 3);
    board_puts(", per-parameter adaptive from 1.5x levels ");
    put_fixed(rms_par * 1e3f, 3);
    board_puts(" / ");
    put_fixed(peak_par * 1e3f, 3);
    board_puts("\nper-parameter estimates (N m): fc+ ");
    put_fixed(est.fc_pos, 4);
    board_puts(", fc- ");
    put_fixed(est.fc_neg, 4);
    board_puts("; supervisor mode ");
    put_int(status.mode);
    board_puts(", switches ");
    put_int(status.switches);
    board_puts("\n");
    if (!(rms_obs * 10.0f < rms_none)) {
        board_puts("FAIL: the observer does not cut the RMS error tenfold\n");
        return 1;
    }
    if (!(rms_par * 10.0f < rms_none)) {
        board_puts("FAIL: the per-parameter servo does not cut the RMS error tenfold\n");
        return 1;
    }
    if (cost()) return 1;
    board_puts("c-abi-done\n");
    return 0;
}

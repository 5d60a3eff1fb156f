/* incline.h: the analytic solution of the paper's validation (Figs. 7 and
 * 8): a rigid body sliding on an incline with Coulomb friction. The one
 * definition, for `clothsim sweep --analytic incline` (app/sweep_metrics.c)
 * and the tests (tests/incline_analytic.h). Header only, plain C: numbers
 * in, numbers out.
 *
 * Along the slope, s measured downhill from the start, with initial speed
 * v0 (negative: uphill):
 *   sliding downhill (v > 0)  a = g (sin theta - mu cos theta)
 *   sliding uphill (v < 0)    a = g (sin theta + mu cos theta)  (friction
 *                             and gravity both pull downhill)
 *   at rest                   stays if mu >= tan theta, else slides
 *                             downhill from rest
 * so s(t) = v0 t + a t^2 / 2 until v reaches 0, when a decelerating body
 * stops (and then stays, or turns round when gravity beats friction). */
#ifndef CS_COMMON_INCLINE_H
#define CS_COMMON_INCLINE_H

#include <math.h>

typedef struct cs_incline {
    double g;          /* |gravity|, m/s^2 */
    double sin_theta;  /* the slope's angle theta from the horizontal */
    double cos_theta;
    double mu;         /* Coulomb coefficient */
    double v0;         /* initial speed along the slope, downhill positive, m/s */
} cs_incline;

/* The incline of angle theta_deg (degrees) under g. */
static inline cs_incline cs_incline_make(double g, double theta_deg, double mu, double v0)
{
    double th = theta_deg * M_PI / 180.0;
    cs_incline p = {g, sin(th), cos(th), mu, v0};
    return p;
}

/* The acceleration downhill while sliding downhill (negative: decelerating). */
static inline double cs_incline_accel_down(const cs_incline *p)
{
    return p->g * (p->sin_theta - p->mu * p->cos_theta);
}

/* The time a body sliding at v0 comes to rest for good (friction holds it),
 * or INFINITY when it never does (gravity beats friction) and 0 when it
 * starts at rest and stays. */
static inline double cs_incline_stop_time(const cs_incline *p)
{
    double down = cs_incline_accel_down(p), up = p->g * (p->sin_theta + p->mu * p->cos_theta);
    if (down > 0)
        return INFINITY; /* once moving downhill, it never stops */
    double t = 0;
    double v = p->v0;
    if (v < 0)
        t += up > 0 ? -v / up : INFINITY, v = 0;
    return v > 0 ? t - v / down : t;
}

/* Distance s (downhill positive) and velocity v along the slope at time t. */
static inline void cs_incline_motion(const cs_incline *p, double t, double *s, double *v)
{
    double down = cs_incline_accel_down(p), up = p->g * (p->sin_theta + p->mu * p->cos_theta);
    double s0 = 0, v0 = p->v0;
    if (v0 < 0) { /* uphill first: decelerates at `up` until it stops */
        double t1 = up > 0 ? -v0 / up : INFINITY;
        if (t <= t1) {
            *s = v0 * t + 0.5 * up * t * t;
            *v = v0 + up * t;
            return;
        }
        s0 = v0 * t1 + 0.5 * up * t1 * t1;
        t -= t1;
        v0 = 0;
    }
    if (v0 == 0 && !(down > 0)) { /* at rest, friction holds it */
        *s = s0;
        *v = 0;
        return;
    }
    if (down < 0 && t > -v0 / down) /* decelerating: stopped, and stays */
        t = -v0 / down;
    *s = s0 + v0 * t + 0.5 * down * t * t;
    *v = v0 + down * t;
}

#endif

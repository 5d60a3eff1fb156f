/* runaway.c: instability detection.
 *
 * A blow-up of the explicit elastic forces, a solve gone astray or a
 * collision response that adds energy all show as cloth moving far faster
 * than anything in the scene can drive it. The bound is a function of the
 * scene, the time and the scripts' lag (state every rank shares and a resume
 * restores), so it is the same on every rank and after a resume:
 *
 *   limit(t) = 10 (v0 + |g| t + body(t) + script(t) + wind) + c / 4 + 1 m/s
 *
 * v0 the fastest initial velocity; |g| t what gravity can give since the
 * start; body(t) and script(t) the fastest surface point of a moving body
 * or a scripted vertex set so far, |v| + |w| r over its extent (cloth keeps
 * what a driver gave it after the driver stops; a held script's at its own,
 * lagging clock); wind the fastest the wind can blow (cs_wind_max_speed);
 * c the fastest elastic wave, sqrt(E L0 / m) over the edge
 * springs: a stretch of strain e released sends its ends back at e c, and
 * cloth that was stretched by a quarter is far beyond Table 1's (stiff
 * cloth, c of hundreds of m/s). The factor 10 leaves room for whips and
 * snaps (a cloth corner can outrun what drives it); a real blow-up grows
 * geometrically and passes any such bound within a few steps.
 * An unbounded body that rotates (a spinning plane) has no finite surface
 * speed: the limit is then infinite and only NaN is caught.
 *
 * Each stage that produces a velocity checks its result on the owned free
 * particles (no message); the end of the step's reduction, which every step
 * already makes for NaN, carries the verdict and the first stage. */
#include "sim/body_grid.h"
#include "sim/internal.h"
#include "sim/vec3.h"

#include <math.h>

enum { SPEED_FACTOR = 10 };
static const double SPEED_FLOOR = 1.0; /* m/s: still scenes */
/* the strain whose release the bound allows for: a quarter (c / 4 above) */
static const double RELEASED_STRAIN = 0.25;

void cs_runaway_init(cs_sim *sim)
{
    double v0 = 0, wave = 0;
    for (int i = 0; i < sim->n; i++)
        v0 = fmax(v0, cs_norm(sim->v + 3 * i));
    const cs_springs *sp = &sim->springs;
    for (int s = 0; s < sp->nedge; s++) { /* sqrt(E L0 / m): a chain's wave speed */
        double m = fmin(sim->mass[sp->ends[2 * s]], sim->mass[sp->ends[2 * s + 1]]);
        wave = fmax(wave, sqrt(sp->stiffness[s] * sp->rest_length[s] / m));
    }
    sim->runaway.initial_speed = v0;
    sim->runaway.wave_speed = wave;
    sim->runaway.stage = -1;
}

/* The fastest point within r of the motion's centre at any time up to t:
 * cloth keeps the speed a driver gave it after the driver stops (a twist
 * whose ends halt whips on), so the bound must not drop when the keys end. */
static double speed_so_far(const cs_motion *m, double t, double r)
{
    return cs_motion_max_speed(m, -INFINITY, t, r);
}

double cs_runaway_limit(const cs_sim *sim, double t)
{
    double drive = sim->runaway.initial_speed + cs_norm(sim->def.gravity) * fabs(t);
    if (sim->def.wind_enabled)
        drive += cs_wind_max_speed(&sim->def.wind);
    /* a script step C held back runs behind its keys (its lag, the same on
     * every rank and restored on resume) and catches up faster: its speed
     * then is that of its own clock, times the catch-up rate. Taking the
     * keys' time instead dropped the bound to the wave term alone when the
     * keys ended while a held twist was still catching up. */
    for (int s = 0; s < sim->nscripts; s++) {
        double lag = sim->script_lag[s];
        drive += speed_so_far(&sim->scripts[s].motion, t - lag, sim->scripts[s].radius) *
                 (lag > 0 ? CS_SCRIPT_CATCH_UP_RATE : 1.0);
    }
    for (int b = 0; b < sim->nbodies; b++) {
        const cs_body_def *body = sim->bodies + b;
        double c[3], w[3], lo[3], hi[3], r = 0;
        cs_motion_pose(&body->motion, t, NULL, c, NULL, w);
        if (cs_norm(w) > 0) {
            if (!cs_body_def_bounds(body, t, lo, hi))
                return INFINITY;
            for (int k = 0; k < 8; k++) { /* the box corner farthest from c */
                double corner[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1],
                                    k & 4 ? hi[2] : lo[2]};
                double d[3];
                cs_sub(corner, c, d);
                r = fmax(r, cs_norm(d));
            }
        }
        drive += speed_so_far(&body->motion, t, r);
    }
    return SPEED_FACTOR * drive + RELEASED_STRAIN * sim->runaway.wave_speed + SPEED_FLOOR;
}

void cs_runaway_begin_step(cs_sim *sim, double t1)
{
    double limit = cs_runaway_limit(sim, t1);
    sim->runaway.limit = limit;
    sim->runaway.limit2 = limit * limit;
}

void cs_runaway_check(cs_sim *sim, const double *v, cs_stage stage)
{
    /* threaded: the largest squared speed and whether any is NaN; a
     * maximum and an or are the same at every thread count */
    double worst = 0;
    int nan_seen = 0;
    const unsigned char *is_free = sim->is_free, *mode = sim->mode;
    /* B.6's velocity at a particle in body contact is not a speed yet: with
     * the improved friction its normal part carries the contact impulse
     * (2 v_n+1/2 - v*, the normal residual of the projected solve), which
     * B.7 turns into friction and removes. A corner slapping the ground at
     * the damped step limit carried 164 m/s there and 3.4 m/s after B.7
     * (the 200 x 200 bench, frame 24), so those particles are checked after
     * B.7, in body_friction's check. */
    bool after_b6 = stage == CS_STAGE_VELOCITY_FULL;
    CS_PARALLEL_FOR_OWNED_WITH(sim->par, i, reduction(max : worst) reduction(|| : nan_seen))
        if (is_free[i] && !(after_b6 && mode[i] == CS_CONTACT))
            cs_speed_seen(v + 3 * i, &worst, &nan_seen);
    cs_runaway_note(sim, stage, worst, nan_seen);
}

void cs_runaway_note(cs_sim *sim, cs_stage stage, double worst, int nan_seen)
{
    if ((nan_seen || worst > sim->runaway.limit2) && sim->runaway.stage < 0) {
        sim->runaway.stage = stage;
        sim->runaway.speed = nan_seen ? NAN : sqrt(worst);
    }
}

int cs_runaway_not_finite(cs_sim *sim, const double *v_next)
{
    int not_finite = 0;
    double *x = sim->x, *v = sim->v;
    CS_PARALLEL_FOR_OWNED_WITH(sim->par, i, reduction(|| : not_finite))
        for (int k = 3 * i; k < 3 * i + 3; k++) {
            if (v_next)
                v[k] = v_next[k];
            if (!isfinite(x[k]) || !isfinite(v[k]))
                not_finite = 1;
        }
    return not_finite;
}

bool cs_runaway_end_step(cs_sim *sim, int not_finite)
{
    /* one reduction: the earliest stage (as STAGE_COUNT - stage, so the
     * maximum wins), the speed seen there, and NaN anywhere in x or v */
    double verdict[2] = {0, 0};
    if (sim->runaway.stage >= 0) {
        verdict[0] = CS_STAGE_COUNT - sim->runaway.stage;
        verdict[1] = isnan(sim->runaway.speed) ? INFINITY : sim->runaway.speed;
    }
    if (not_finite) {
        if (verdict[0] == 0)
            verdict[0] = CS_STAGE_COUNT - CS_STAGE_VELOCITY_FULL;
        verdict[1] = INFINITY;
    }
    cs_par_begin(sim->par, CS_STAGE_VELOCITY_FULL); /* B.6's result checked */
    cs_par_max(sim->par, verdict, 2);
    if (verdict[0] == 0)
        return true;
    sim->runaway.stage = CS_STAGE_COUNT - (int)verdict[0];
    sim->runaway.speed = verdict[1];
    return false;
}

/* scripts.c: pinned and scripted vertices over a step: their targets,
 * their release, and holding them while a limit is computed. */
#include <math.h>
#include <string.h>

#include "sim/internal.h"
#include "sim/vec3.h"

/* Targets of scripted vertices at the end t1 of a step of dt: position and
 * velocity, at the script's own time t1 - lag (lag 0 but after a hold). */
void cs_script_targets(cs_sim *sim, double t1, double dt)
{
    for (int s = 0; s < sim->nscripts; s++) {
        cs_script_state *sc = sim->scripts + s;
        if (sc->released)
            continue;
        double lag0 = sim->script_lag[s];
        double lag1 = fmax(0.0, lag0 - (CS_SCRIPT_CATCH_UP_RATE - 1.0) * dt);
        sim->script_lag[s] = lag1;
        double t = t1 - lag1, rate = 1.0 + (lag0 - lag1) / dt; /* script s per s */
        double R[9], c[3], vel[3], w[3];
        cs_motion_pose(&sc->motion, t, R, c, vel, w);
        for (int d = 0; d < 3; d++) {
            vel[d] *= rate;
            w[d] *= rate;
        }
        for (int j = 0; j < sc->nvertices; j++) {
            int g = sc->vertices[j];
            double r[3], wr[3];
            cs_mat_apply(R, sc->local + 3 * j, r);
            cs_cross(w, r, wr);
            for (int d = 0; d < 3; d++) {
                sim->script_x[3 * g + d] = c[d] + r[d];
                sim->script_v[3 * g + d] = vel[d] + wr[d];
            }
        }
    }
}

/* Scripts whose release time has come let their vertices go, at the start
 * of a step (a function of the time alone: every rank and a resumed run
 * release at the same step). The vertices keep the velocity the script
 * gave them at the end of the last step. */
void cs_scripts_release(cs_sim *sim, double dt)
{
    for (int s = 0; s < sim->nscripts; s++) {
        cs_script_state *sc = sim->scripts + s;
        if (sc->released || !(sc->release_time > 0) || sim->t < sc->release_time - 1e-9 * dt)
            continue;
        sc->released = true;
        for (int j = 0; j < sc->nvertices; j++) {
            int g = sc->vertices[j];
            sim->is_free[g] = 1;
            sim->active[g] = cs_par_owns(sim->par, g);
            if (sim->selfcol)
                cs_selfcol_release(sim->selfcol, g, sim->mass[g]);
        }
    }
}

void cs_scripts_hold_releasable(cs_sim *sim, bool hold)
{
    for (int s = 0; s < sim->nscripts; s++)
        if (sim->scripts[s].release_time > 0 && !sim->scripts[s].released)
            for (int j = 0; j < sim->scripts[s].nvertices; j++)
                sim->is_free[sim->scripts[s].vertices[j]] = !hold;
}

double cs_sim_script_offset(const cs_sim *sim, int *vertex)
{
    double worst = 0;
    *vertex = -1;
    for (int s = 0; s < sim->nscripts; s++) {
        const cs_script_state *sc = sim->scripts + s;
        if (sc->released || (sc->release_time > 0 && sim->t >= sc->release_time))
            continue;
        double R[9], c[3];
        cs_motion_pose(&sc->motion, sim->t - sim->script_lag[s], R, c, NULL, NULL);
        for (int j = 0; j < sc->nvertices; j++) {
            int g = sc->vertices[j];
            double r[3], off[3];
            cs_mat_apply(R, sc->local + 3 * j, r);
            for (int d = 0; d < 3; d++)
                off[d] = c[d] + r[d] - sim->x[3 * g + d];
            if (cs_norm(off) > worst) {
                worst = cs_norm(off);
                *vertex = g;
            }
        }
    }
    return worst;
}

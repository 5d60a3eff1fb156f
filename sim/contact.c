/* contact.c: cloth-object collisions and friction (Section 6).
 *
 * Gamma(v) removes the part of v that moves into the body and applies
 * Coulomb friction in proportion to the normal velocity it removed.
 * The improved method finds where each particle crossed the level set,
 * applies Gamma to v^(n+1/2) to move on from there, keeps Gamma(v^n) for the
 * trapezoidal rule, and applies Gamma again to v_NP after the projected
 * solve (step B.7). The previous method (Bridson et al. 2003) projects the
 * position along the normal instead and applies Gamma after the solve to the
 * projected velocity, whose normal part is already gone.
 */
#include <string.h>

#include "sim/internal.h"
#include "sim/vec3.h"

void cs_gamma(const double v[3], const double N[3], const double vb[3], double mu,
              double out[3])
{
    double vn = cs_dot(v, N), vbn = cs_dot(vb, N);
    double vt[3], vbt[3], vrel[3];
    for (int d = 0; d < 3; d++) {
        vt[d] = v[d] - vn * N[d];
        vbt[d] = vb[d] - vbn * N[d];
        vrel[d] = vt[d] - vbt[d];
    }
    double vn_star = vn > vbn ? vn : vbn;
    double speed = cs_norm(vrel);
    double scale = 0;
    if (speed > 0) {
        scale = 1.0 - mu * (vn_star - vn) / speed;
        if (scale < 0)
            scale = 0;
    }
    for (int d = 0; d < 3; d++)
        out[d] = vn_star * N[d] + vbt[d] + scale * vrel[d];
}

/* Step B.4: sim->x holds x~^(n+1) on entry and x^(n+1) on return; x_prev
 * is x^n, v_half is v~^(n+1/2). Sets v_star = Gamma(v^n) for particles in
 * contact (v^n elsewhere) and marks them CS_CONTACT with their normal. All
 * level set queries use the bodies at time n+1, as the paper prescribes. */
void cs_body_collide(cs_sim *sim, double dt)
{
    double t1 = sim->t + dt;
    bool improved = sim->def.friction_method == CS_FRICTION_IMPROVED;
    memcpy(sim->v_star, sim->v, sizeof *sim->v * 3 * (size_t)sim->n);
    for (int i = 0; i < sim->n; i++) {
        sim->contact_body[i] = -1;
        if (!sim->is_free[i])
            continue;
        double *x = sim->x + 3 * i;
        const double *xn = sim->x_prev + 3 * i;
        double *vh = sim->v_half + 3 * i;
        for (int b = 0; b < sim->nbodies; b++) {
            const cs_body_def *body = sim->bodies + b;
            double N[3], vb[3], vstar[3];
            double phi1 = cs_body_def_phi(body, t1, x, N);
            if (!(phi1 < 0))
                continue;
            if (improved) {
                /* crossing point along the step; phi at time n of the point
                 * x^n is phi_{n+1}(x^n) + dt v_BN (the body moved since) */
                double Nn[3];
                double phi0 = cs_body_def_phi(body, t1, xn, Nn);
                cs_body_def_velocity(body, t1, xn, vb);
                phi0 += dt * cs_dot(vb, N);
                double theta = phi0 > 0 ? phi0 / (phi0 - phi1) : 0.0;
                if (theta > 1)
                    theta = 1;
                double xc[3];
                for (int d = 0; d < 3; d++)
                    xc[d] = xn[d] + theta * (x[d] - xn[d]);
                double Nc[3];
                cs_body_def_phi(body, t1, xc, Nc);
                memcpy(N, Nc, sizeof N);
                cs_body_def_velocity(body, t1, xc, vb);
                cs_gamma(vh, N, vb, body->friction, vstar);
                memcpy(vh, vstar, sizeof vstar);
                for (int d = 0; d < 3; d++)
                    x[d] = xc[d] + (1.0 - theta) * dt * vstar[d];
                /* On curved or turning bodies the linearisation can leave the
                 * point a little inside: finish along the normal there. */
                double g[3], phi = cs_body_def_phi(body, t1, x, g);
                if (phi < 0)
                    cs_axpy(-phi, g, x);
            } else {
                cs_axpy(-phi1, N, x); /* Fig. 6 left: straight out along N */
                cs_body_def_velocity(body, t1, x, vb);
            }
            cs_gamma(sim->v + 3 * i, N, vb, body->friction, sim->v_star + 3 * i);
            memcpy(sim->contact_normal + 3 * i, N, sizeof N);
            sim->contact_body[i] = b;
        }
        if (sim->contact_body[i] >= 0) {
            sim->mode[i] = CS_CONTACT;
            sim->contacts++;
        }
    }
}

/* Step B.7: v_next holds v~^(n+1) (from v_NP for the improved method);
 * apply Gamma with the contact normal and the body's velocity at n+1. */
void cs_body_friction(cs_sim *sim, double dt)
{
    double t1 = sim->t + dt;
    for (int i = 0; i < sim->n; i++) {
        int b = sim->contact_body[i];
        if (b < 0)
            continue;
        double vb[3], out[3];
        cs_body_def_velocity(sim->bodies + b, t1, sim->x + 3 * i, vb);
        cs_gamma(sim->v_next + 3 * i, sim->contact_normal + 3 * i, vb,
                 sim->bodies[b].friction, out);
        memcpy(sim->v_next + 3 * i, out, sizeof out);
    }
}

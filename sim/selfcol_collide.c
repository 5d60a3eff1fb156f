/* selfcol_collide.c: step C (Section 4): continuous collisions between
 * the last collision-free positions and the candidates, their Gauss-Seidel
 * response, and impact zones moved rigidly. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sim/ccd.h"
#include "sim/selfcol_private.h"
#include "sim/vec3.h"

/* ------------------------------------------------------------- step C */

/* Positions of a pair's particles at time t of the trajectories. */
static void pair_at(const cs_selfcol *sc, const cs_pair *p, const double *x, double t,
                    double out[12])
{
    for (int k = 0; k < 4; k++)
        for (int d = 0; d < 3; d++) {
            double a = sc->x_free[3 * p->v[k] + d], b = x[3 * p->v[k] + d];
            out[3 * k + d] = a + t * (b - a);
        }
}

/* The conservative filter before any root finding. Along linear
 * trajectories the relative position of the pair at fixed weights moves by
 * a convex combination of the displacements of one side's vertices
 * relative to the other's, so the distance between the primitives never
 * drops faster than the largest such relative displacement ("reach"): a
 * pair farther apart at the start than the proximity tolerance plus its
 * reach cannot collide over the span. A sheet moving rigidly (reach 0) is
 * settled by one distance per pair instead of a vanishing cubic sampled 31
 * times. The slack covers the round-off of the distances compared. */
static bool out_of_reach(const cs_selfcol *sc, bool is_edge, const double *x0, const double *dx)
{
    int split = is_edge ? 2 : 3; /* one side: vertices [0, split) */
    double reach2 = 0, scale = 0;
    for (int i = 0; i < split; i++)
        for (int j = split; j < 4; j++) {
            double r[3];
            cs_sub(dx + 3 * j, dx + 3 * i, r);
            double r2 = cs_dot(r, r);
            reach2 = r2 > reach2 ? r2 : reach2;
        }
    for (int k = 0; k < 12; k++)
        scale = fabs(x0[k]) + fabs(dx[k]) > scale ? fabs(x0[k]) + fabs(dx[k]) : scale;
    double need = sc->proximity + sqrt(reach2);
    need += 64 * DBL_EPSILON * (scale + need);
    /* a separating axis of the start boxes bounds the distance first */
    const double *const pts[4] = {x0, x0 + 3, x0 + 6, x0 + 9};
    if (sc_sides_apart(pts, split, need))
        return true;
    double d0, w[3], s, t;
    if (is_edge)
        d0 = cs_segment_segment_closest(x0, x0 + 3, x0 + 6, x0 + 9, &s, &t);
    else
        d0 = cs_point_triangle_closest(x0 + 9, x0, x0 + 3, x0 + 6, w);
    return d0 > need;
}

/* Continuous test: the first coplanar time at which the pair comes within
 * the proximity tolerance; fills the weights c and a unit normal oriented
 * from the free state's side. */
static bool pair_collides(const cs_selfcol *sc, const cs_pair *p, bool is_edge, const double *x,
                          double c[4], double n[3])
{
    double x0[12], x1[12], dx[12], times[CS_CCD_MAX_TIMES];
    pair_at(sc, p, x, 0, x0);
    pair_at(sc, p, x, 1, x1);
    for (int k = 0; k < 12; k++)
        dx[k] = x1[k] - x0[k];
    if (out_of_reach(sc, is_edge, x0, dx))
        return false;
    int nt = cs_coplanarity_times(x0, x0 + 3, x0 + 6, x0 + 9, dx, dx + 3, dx + 6, dx + 9, times);
    for (int i = 0; i < nt; i++) {
        double xt[12], dist, w[3], s, t;
        for (int k = 0; k < 12; k++)
            xt[k] = x0[k] + times[i] * dx[k];
        if (!is_edge) {
            dist = cs_point_triangle_closest(xt + 9, xt, xt + 3, xt + 6, w);
            c[0] = -w[0], c[1] = -w[1], c[2] = -w[2], c[3] = 1;
        } else {
            dist = cs_segment_segment_closest(xt, xt + 3, xt + 6, xt + 9, &s, &t);
            c[0] = -(1 - s), c[1] = -s, c[2] = 1 - t, c[3] = t;
        }
        if (!(dist < sc->proximity))
            continue;
        /* normal at the collision time: the triangle's, or the two edges'
         * common perpendicular; falling back on the separation direction */
        double e1[3], e2[3];
        if (!is_edge) {
            cs_sub(xt + 3, xt, e1);
            cs_sub(xt + 6, xt, e2);
        } else {
            cs_sub(xt + 3, xt, e1);
            cs_sub(xt + 9, xt + 6, e2);
        }
        cs_cross(e1, e2, n);
        double len = cs_norm(n);
        double rel0[3] = {0, 0, 0}, relv[3] = {0, 0, 0};
        for (int k = 0; k < 4; k++) {
            cs_axpy(c[k], x0 + 3 * k, rel0);
            cs_axpy(c[k], dx + 3 * k, relv);
        }
        if (!(len > 1e-12 * (cs_dot(e1, e1) + cs_dot(e2, e2)))) {
            memcpy(n, rel0, sizeof rel0);
            len = cs_norm(n);
            if (!(len > 0)) {
                memcpy(n, relv, sizeof relv);
                len = cs_norm(n);
                if (!(len > 0))
                    continue; /* nothing moves and nothing separates: no impulse helps */
            }
        }
        for (int k = 0; k < 3; k++)
            n[k] /= len;
        /* orient from the side the pair started on; starting in contact, the
         * side the point's cloth is on; failing that, against the approach */
        double side = cs_dot(rel0, n);
        if (!is_edge && fabs(side) <= 1e-12 * cs_norm(rel0))
            side = sc_ring_side(sc, sc->x_free, p->v[3], n);
        if (side < 0 || (side == 0 && cs_dot(relv, n) > 0))
            for (int k = 0; k < 3; k++)
                n[k] = -n[k];
        /* in contact at the start and moving apart: that is the response
         * of an earlier pass working, not a collision */
        if (times[i] == 0 && cs_dot(relv, n) >= 0)
            continue;
        return true;
    }
    return false;
}

/* A colliding pair's history, as step A gives its pairs: the side it
 * started on in the collision-free state (nrm, from pair_collides). An
 * edge/edge pair keeps it as s0; a point/triangle pair is wound so the
 * triangle's normal points at that side. Without it the elastic push of
 * the response reads no history (an edge pair) or pushes a point that came
 * from behind a triangle through it (a point pair). */
static void set_history(const cs_selfcol *sc, cs_pair *p, bool is_edge, const double nrm[3])
{
    memcpy(p->s0, nrm, sizeof p->s0);
    if (is_edge)
        return;
    const double *x = sc->x_free;
    double e1[3], e2[3], wn[3];
    cs_sub(x + 3 * p->v[1], x + 3 * p->v[0], e1);
    cs_sub(x + 3 * p->v[2], x + 3 * p->v[0], e2);
    cs_cross(e1, e2, wn);
    if (cs_dot(wn, nrm) < 0) {
        int swap = p->v[1];
        p->v[1] = p->v[2];
        p->v[2] = swap;
    }
}

typedef struct collector {
    const cs_selfcol *sc;
    const cs_par *par;
    const double *x;
} collector;

/* The pair (v) this rank finds, if it collides, with its history. */
static bool collision_of(const collector *cl, const int v[4], bool is_edge, cs_pair *out)
{
    if (sc_pair_rank(cl->par, v) != cl->par->rank)
        return false;
    memcpy(out->v, v, sizeof out->v);
    double c[4], nrm[3];
    if (!pair_collides(cl->sc, out, is_edge, cl->x, c, nrm))
        return false;
    set_history(cl->sc, out, is_edge, nrm);
    return true;
}

static bool make_collision_point_triangle(const void *ctx, int point, int t, cs_pair *out)
{
    const collector *cl = ctx;
    const int *tri = cl->sc->tri + 3 * t;
    if (point == tri[0] || point == tri[1] || point == tri[2])
        return false; /* wings stay: a wing point crossing drags its other triangles through */
    int v[4] = {tri[0], tri[1], tri[2], point};
    return collision_of(cl, v, false, out);
}

static bool make_collision_edge_edge(const void *ctx, int ea, int eb, cs_pair *out)
{
    const collector *cl = ctx;
    const int *a = cl->sc->edge + 2 * ea, *b = cl->sc->edge + 2 * eb;
    if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1])
        return false;
    int v[4] = {a[0], a[1], b[0], b[1]};
    return collision_of(cl, v, true, out);
}

/* D = the particles' mean displacement from x_free to x */
static void mean_displacement(const cs_selfcol *sc, const double *x, double D[3])
{
    D[0] = D[1] = D[2] = 0;
    for (int i = 0; i < sc->n; i++)
        for (int d = 0; d < 3; d++)
            D[d] += x[3 * i + d] - sc->x_free[3 * i + d];
    for (int d = 0; d < 3; d++)
        D[d] = sc->n ? D[d] / sc->n : 0;
}

/* Swept boxes from the free positions to x, and the pairs among their
 * primitives that collide along the trajectories, with their history (only
 * near changed particles when only_dirty). The boxes sweep in a frame
 * moving with the cloth's mean displacement D over the span: two points
 * meet at time s exactly when they meet after both are moved back by s D,
 * and those moved trajectories are straight lines too, so a sheet falling
 * rigidly sweeps no volume at all. Returns how many, or -1 when memory ran
 * out. */
static long find_collisions(cs_selfcol *sc, const cs_par *par, const double *x,
                            double thickness, bool only_dirty)
{
    double pad = sc->proximity, D[3];
    mean_displacement(sc, x, D);
#pragma omp parallel for schedule(static)
    for (int i = 0; i < sc->n; i++) {
        cs_box *b = sc->pbox + i;
        double end[3];
        cs_sub(x + 3 * i, D, end);
        cs_box_empty(b);
        cs_box_add_point(b, sc->x_free + 3 * i);
        cs_box_add_point(b, end);
        cs_box_thicken(b, pad);
        sc->pdirty[i] = sc->vdirty[i];
    }
#pragma omp parallel for schedule(static)
    for (int k = 0; k < sc->ne; k++) {
        cs_box *b = sc->ebox + k;
        int i = sc->edge[2 * k], j = sc->edge[2 * k + 1];
        *b = sc->pbox[i];
        cs_box_add_point(b, sc->pbox[j].lo);
        cs_box_add_point(b, sc->pbox[j].hi);
        sc->edirty[k] = sc->vdirty[i] | sc->vdirty[j];
    }
#pragma omp parallel for schedule(static)
    for (int k = 0; k < sc->nt; k++) {
        cs_box *b = sc->tbox + k;
        const int *t = sc->tri + 3 * k;
        *b = sc->pbox[t[0]];
        cs_box_add_point(b, sc->pbox[t[1]].lo);
        cs_box_add_point(b, sc->pbox[t[1]].hi);
        cs_box_add_point(b, sc->pbox[t[2]].lo);
        cs_box_add_point(b, sc->pbox[t[2]].hi);
        sc->tdirty[k] = sc->vdirty[t[0]] | sc->vdirty[t[1]] | sc->vdirty[t[2]];
    }
    sc->cpt.n = sc->cee.n = 0;
    collector cl = {sc, par, x};
    if (sc_cache_update(sc, par->rank, thickness, NULL, NULL, NULL) ||
        sc_find_pairs(sc, false, only_dirty, NULL, NULL, make_collision_point_triangle, &cl,
                      &sc->cpt) ||
        sc_find_pairs(sc, true, only_dirty, NULL, NULL, make_collision_edge_edge, &cl, &sc->cee))
        return -1;
    return sc->cpt.n + sc->cee.n;
}

/* True when no pair can come within the proximity tolerance over the span,
 * so that the first search would find nothing: every pair's sides start
 * at least start_gap apart (step A), and a pair's reach (out_of_reach) is
 * at most twice the largest displacement of a particle relative to the
 * cloth's mean one. A sheet in free fall, or draped and still, is settled
 * by one pass over its particles instead of a search of its candidates.
 * The slack is above out_of_reach's, so whenever this holds, every pair's
 * own test would have said so. */
static bool all_out_of_reach(cs_selfcol *sc, const double *x)
{
    if (!sc->use_start_gap || !(sc->start_gap > 0))
        return false;
    double D[3], reach2 = 0, scale = 0;
    int not_finite = 0;
    mean_displacement(sc, x, D);
#pragma omp parallel for schedule(static) reduction(max : reach2, scale) reduction(|| : not_finite)
    for (int i = 0; i < sc->n; i++) {
        double r2 = 0;
        for (int d = 0; d < 3; d++) {
            double a = sc->x_free[3 * i + d], dx = x[3 * i + d] - a, r = dx - D[d];
            r2 += r * r;
            scale = fmax(scale, fabs(a) + fabs(dx));
        }
        reach2 = fmax(reach2, r2);
        not_finite = not_finite || !isfinite(r2) || !isfinite(scale);
    }
    if (not_finite)
        return false;
    double need = sc->proximity + 2 * sqrt(reach2);
    need += 1e-9 * need + 256 * DBL_EPSILON * (scale + need);
    if (!(sc->start_gap > need))
        return false;
    sc->stats.searches_skipped++;
    return true;
}

/* Symmetric 3x3 eigen decomposition by cyclic Jacobi rotations:
 * A = Q diag(l) Q^T, Q's columns the eigenvectors. */
static void eigen_symmetric(const double A_in[9], double l[3], double Q[9])
{
    double A[9];
    memcpy(A, A_in, sizeof A);
    for (int k = 0; k < 9; k++)
        Q[k] = (k % 4 == 0) ? 1 : 0;
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = fabs(A[1]) + fabs(A[2]) + fabs(A[5]);
        if (off <= 1e-300 || off < 1e-18 * (fabs(A[0]) + fabs(A[4]) + fabs(A[8])))
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                double apq = A[3 * p + q];
                if (apq == 0)
                    continue;
                double theta = (A[3 * q + q] - A[3 * p + p]) / (2 * apq);
                double t = copysign(1.0, theta) / (fabs(theta) + sqrt(theta * theta + 1));
                double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 3; k++) { /* A = J^T A J */
                    double akp = A[3 * k + p], akq = A[3 * k + q];
                    A[3 * k + p] = c * akp - s * akq;
                    A[3 * k + q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) {
                    double apk = A[3 * p + k], aqk = A[3 * q + k];
                    A[3 * p + k] = c * apk - s * aqk;
                    A[3 * q + k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; k++) {
                    double qkp = Q[3 * k + p], qkq = Q[3 * k + q];
                    Q[3 * k + p] = c * qkp - s * qkq;
                    Q[3 * k + q] = s * qkp + c * qkq;
                }
            }
    }
    l[0] = A[0], l[1] = A[4], l[2] = A[8];
}

void cs_impact_zone_motion(int n, const int *idx, const double *m, const double *xf,
                           const double *u, double span, double *x, double vcm[3],
                           double omega[3])
{
    double M = 0, xcm[3] = {0, 0, 0};
    vcm[0] = vcm[1] = vcm[2] = 0;
    for (int k = 0; k < n; k++) {
        int i = idx[k];
        M += m[i];
        cs_axpy(m[i], xf + 3 * i, xcm);
        cs_axpy(m[i], u + 3 * i, vcm);
    }
    for (int d = 0; d < 3; d++) {
        xcm[d] /= M;
        vcm[d] /= M;
    }
    double L[3] = {0, 0, 0}, I[9] = {0};
    for (int k = 0; k < n; k++) {
        int i = idx[k];
        double r[3], du[3], rxu[3];
        cs_sub(xf + 3 * i, xcm, r);
        cs_sub(u + 3 * i, vcm, du);
        cs_cross(r, du, rxu);
        cs_axpy(m[i], rxu, L);
        double rr = cs_dot(r, r);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                I[3 * a + b] += m[i] * ((a == b ? rr : 0) - r[a] * r[b]);
    }
    /* omega = I^+ L: eigenvalues below round-off of the largest count as
     * zero (coplanar, colinear, coincident points) */
    double l[3], Q[9];
    eigen_symmetric(I, l, Q);
    double lmax = fmax(fabs(l[0]), fmax(fabs(l[1]), fabs(l[2])));
    double qL[3];
    cs_mat_apply_transpose(Q, L, qL);
    for (int k = 0; k < 3; k++)
        qL[k] = fabs(l[k]) > 1e-12 * lmax && l[k] != 0 ? qL[k] / l[k] : 0;
    cs_mat_apply(Q, qL, omega);
    double q[4], R[9];
    cs_quat_from_rotation_vector(omega, span, q);
    cs_quat_to_matrix(q, R);
    for (int k = 0; k < n; k++) {
        int i = idx[k];
        double r[3], Rr[3];
        cs_sub(xf + 3 * i, xcm, r);
        cs_mat_apply(R, r, Rr);
        for (int d = 0; d < 3; d++)
            x[3 * i + d] = xcm[d] + span * vcm[d] + Rr[d];
    }
}

/* True when the zone's listed particles include vertices of two scripts
 * (two pins, a pin and a script, two ends turning apart): no rigid motion
 * keeps both on their paths. */
static bool zone_spans_scripts(const cs_sim *sim, const int *list, int count)
{
    int first = -1;
    for (int k = 0; k < count; k++) {
        int i = list[k];
        if (sim->is_free[i])
            continue;
        int s = sim->script_of[i];
        if (first < 0)
            first = s;
        else if (s != first)
            return true;
    }
    return false;
}

/* Script s back where it was at the outer step's start (its x_free, the
 * pose at its clock then), all its vertices, and its clock with them: at
 * the step's end it is span more behind. x_before keeps where step C puts
 * a script's vertices, so a later rigid zone leaves them there too. Once
 * per script and step C: a held script's lag is lag_start + span, which the
 * steps' catching up (lag only shrinks from lag_start) never reaches, so a
 * zone's other vertices of the same script find it held already. */
static void hold_script(cs_sim *sim, int s, double span)
{
    cs_selfcol *sc = sim->selfcol;
    const cs_script_state *script = sim->scripts + s;
    double held_lag = sim->script_lag_start[s] + span;
    if (script->released || sim->script_lag[s] == held_lag)
        return;
    for (int j = 0; j < script->nvertices; j++) {
        int i = script->vertices[j];
        memcpy(sim->x + 3 * i, sc->x_free + 3 * i, 3 * sizeof(double));
        memcpy(sc->x_before + 3 * i, sc->x_free + 3 * i, 3 * sizeof(double));
        sc->vdirty[i] = 1;
    }
    sim->script_lag[s] = held_lag;
}

/* Zone root's particles into sc->zone_list; returns how many. */
static int zone_members(cs_selfcol *sc, int root)
{
    int count = 0;
    for (int i = 0; i < sc->n; i++)
        if (sc->zone[i] >= 0 && sc_zone_find(sc->zone, i) == root)
            sc->zone_list[count++] = i;
    return count;
}

/* A zone no end state could follow its scripts in: its size, scripts and
 * where (step C then stops the run, CS_ERR_SCRIPT). */
static void note_conflict(cs_sim *sim, const int *list, int count)
{
    cs_script_conflict *why = &sim->selfcol->conflict;
    why->found = true;
    why->t = sim->t;
    why->zone_size = count;
    why->nscripts = 0;
    why->more_scripts = false;
    for (int k = 0; k < count; k++) {
        int i = list[k];
        if (sim->is_free[i])
            continue;
        int s = sim->script_of[i], seen = 0;
        while (seen < why->nscripts && why->scripts[seen] != s)
            seen++;
        if (seen < why->nscripts)
            continue;
        if (why->nscripts < 4)
            why->scripts[why->nscripts++] = s;
        else
            why->more_scripts = true;
    }
}

/* Moves every impact zone: rigidly, with pinned and scripted particles
 * far heavier than the rest and kept at their prescribed positions; a zone
 * that holds vertices of two prescribed motions, which no rigid motion
 * follows, by the projection of selfcol_project.c (script_zones: follow),
 * or held where it was collision free with its scripts (hold_script: they
 * wait, then catch up in scripts.c's cs_script_targets). Returns false when a
 * zone has no answer that follows its scripts (sc->conflict says which). */
static bool move_zones(cs_sim *sim, double span, double *dv)
{
    cs_selfcol *sc = sim->selfcol;
    int n = sc->n;
    bool follow = sim->def.self.script_zones == CS_SCRIPT_ZONES_FOLLOW, ok = true;
    /* scratch, free during step C: v_half, and CG's explicit start */
    double *u = sim->v_half, *mw = sim->cg.explicit_z;
    double heaviest = 0;
    for (int i = 0; i < n; i++)
        heaviest = fmax(heaviest, sim->mass[i]);
    for (int i = 0; i < n; i++) {
        for (int d = 0; d < 3; d++)
            u[3 * i + d] = (sim->x[3 * i + d] - sc->x_free[3 * i + d]) / span;
        mw[i] = sim->is_free[i] ? sim->mass[i] : 1e6 * heaviest;
    }
    for (int root = 0; root < n; root++) {
        if (sc->zone[root] < 0 || sc_zone_find(sc->zone, root) != root)
            continue;
        int count = zone_members(sc, root);
        double vcm[3], w[3];
        bool spans = zone_spans_scripts(sim, sc->zone_list, count);
        if (spans && follow) {
            sc->stats.projected_zones++;
            if (!sc_project_zone(sc, root, sim->x, &sc->conflict)) {
                note_conflict(sim, sc->zone_list, count);
                ok = false;
            }
        } else if (spans) {
            for (int k = 0; k < count; k++) {
                int i = sc->zone_list[k];
                memcpy(sim->x + 3 * i, sc->x_free + 3 * i, 3 * sizeof(double));
                if (!sim->is_free[i])
                    hold_script(sim, sim->script_of[i], span);
            }
            sc->stats.held_zones++;
        } else {
            cs_impact_zone_motion(count, sc->zone_list, mw, sc->x_free, u, span, sim->x, vcm, w);
        }
        for (int k = 0; k < count; k++) {
            int i = sc->zone_list[k];
            if (!sim->is_free[i])
                memcpy(sim->x + 3 * i, sc->x_before + 3 * i, 3 * sizeof(double));
            for (int d = 0; d < 3; d++) /* a zone is an inelastic merge: v follows */
                dv[3 * i + d] += (sim->x[3 * i + d] - sc->x_free[3 * i + d]) / span - u[3 * i + d];
            sc->vdirty[i] = 1;
        }
        if (count > sc->stats.max_zone)
            sc->stats.max_zone = count;
        for (int k = 1; k < count; k++)
            if (sim->par->owner[sc->zone_list[k]] != sim->par->owner[sc->zone_list[0]]) {
                sc->stats.zones_across++;
                break;
            }
    }
    return ok;
}

/* One colliding pair's response in step C: inelastic on the effective
 * velocities u (the real velocity's change accumulates in dv), then an
 * elastic push if the end positions are too close. Returns false when the
 * pair no longer collides (an earlier response moved it). */
static bool collision_respond(cs_selfcol *sc, const cs_pair *p, bool is_edge, double *x,
                              double *u, double *dv, double span, const response *elastic)
{
    double c[4], nrm[3];
    if (!pair_collides(sc, p, is_edge, x, c, nrm))
        return false;
    double inv_m = sc_pair_inverse_mass(sc, p, c), rel[3];
    if (!(inv_m > 0))
        return true;
    double un = sc_pair_normal_velocity(p, c, u, nrm, rel);
    if (un < 0) {
        double J = -un / sc_pair_impulse_inverse_mass(sc, p, c, inv_m);
        sc_pair_impulse(sc, p, c, J, nrm, u);
        sc_pair_impulse(sc, p, c, J, nrm, dv);
    }
    for (int q = 0; q < 4; q++) {
        int i = p->v[q];
        for (int e = 0; e < 3; e++)
            x[3 * i + e] = sc->x_free[3 * i + e] + span * u[3 * i + e];
    }
    if (sc_pair_respond(sc, p, is_edge, x, u, elastic))
        for (int q = 0; q < 4; q++) {
            int i = p->v[q];
            for (int e = 0; e < 3; e++)
                x[3 * i + e] = sc->x_free[3 * i + e] + span * u[3 * i + e];
        }
    return true;
}

static void respond_all(cs_selfcol *sc, const cs_pair_list *pt, const cs_pair_list *ee,
                        double *x, double *u, double *dv, double span, const response *elastic)
{
    for (int j = 0; j < pt->n; j++)
        collision_respond(sc, pt->p + j, false, x, u, dv, span, elastic);
    for (int j = 0; j < ee->n; j++)
        collision_respond(sc, ee->p + j, true, x, u, dv, span, elastic);
}

/* True when step C keeps the zone passes' collisions for the projection of
 * zones across prescribed motions: scripts to follow (pins alone are one
 * motion, which a rigid zone follows). */
static bool keeps_constraints(const cs_sim *sim)
{
    return sim->nscripts > 0 && sim->def.self.script_zones == CS_SCRIPT_ZONES_FOLLOW;
}

/* Impact zones over all ranks: every rank merges every colliding pair's
 * particles in the same order, so all hold the same zones, and keeps the
 * same constraints for the projection. Returns 0 or -1. */
static int merge_zones(cs_sim *sim)
{
    cs_selfcol *sc = sim->selfcol;
    int nmine = sc->cpt.n + sc->cee.n;
    int *mine = malloc(sizeof *mine * 5 * ((size_t)nmine + 1));
    if (!mine)
        return -1;
    for (int l = 0, m = 0; l < 2; l++) {
        const cs_pair_list *list = l == 0 ? &sc->cpt : &sc->cee;
        for (int j = 0; j < list->n; j++, m++) {
            memcpy(mine + 5 * m, list->p[j].v, 4 * sizeof *mine);
            mine[5 * m + 4] = l; /* an edge pair */
        }
    }
    void *gathered;
    int nall;
    int rc = cs_par_allgather_items(sim->par, mine, nmine, 5 * sizeof *mine, &gathered, &nall);
    free(mine);
    if (rc)
        return -1;
    const int *all = gathered;
    bool keep = keeps_constraints(sim);
    for (int k = 0; k < nall; k++) {
        const int *v = all + 5 * k;
        for (int q = 1; q < 4; q++)
            sc_zone_union(sc->zone, v[0], v[q]);
        cs_pair p;
        double c[4], nrm[3];
        memcpy(p.v, v, sizeof p.v);
        if (keep && pair_collides(sc, &p, v[4] != 0, sim->x, c, nrm) &&
            sc_zone_constraint_add(sc, v, c, nrm, sim->def.self.thickness) != 0)
            rc = -1;
    }
    free(gathered);
    return rc;
}

/* Step C on several ranks: each pass starts from positions synchronised to
 * every rank; each rank finds its assigned colliding pairs; responses run
 * in Fig. 12's two phases (components of boundary pairs, results sent to
 * the owners, then internal pairs); the pass count, the decision to stop
 * and the impact zones are global. On one rank there are no messages and
 * no boundary pairs. */
long cs_selfcol_collide(cs_sim *sim, double span, int k, bool detect_only)
{
    cs_selfcol *sc = sim->selfcol;
    cs_par *par = sim->par;
    const cs_self_collision_def *d = &sim->def.self;
    int n = sc->n;
    double *x = sim->x;
    size_t bytes = sizeof(double) * 3 * (size_t)n;
    cs_par_allgather(par, x, 3);
    memcpy(sc->x_before, x, bytes);
    for (int i = 0; i < n; i++) {
        sc->vdirty[i] = 1;
        sc->zone[i] = -1;
    }
    /* elastic repulsion after a collision uses the average step of the
     * loop, not the whole span: later steps' repulsions do the rest */
    response elastic = {false, true, false, span / (k > 0 ? k : 1), d->thickness, d->stiffness,
                        0, d->edge_flip_epsilon};
    double *u = sim->v_next; /* effective velocities; scratch between steps */
    /* The real velocity takes the inelastic changes only (impulses and
     * zones); the elastic push moves positions, as in B.2 (Section 5). */
    double *dv = sim->v0;
    memset(dv, 0, bytes);
    sc->nkc = 0;
    sc->conflict.found = false;
    long projected_before = sc->stats.projected_zones, first_pass = 0;
    int zones_formed = 0;
    for (int pass = 0;; pass++) {
        if (pass > 0) { /* what moved since the last pass, on any rank */
            cs_par_allgather(par, x, 3);
            /* moved, or in a pair the last pass found: that pair may
             * collide still though its response moved nothing (held
             * particles, no approach) */
            for (int i = 0; i < n; i++)
                sc->vdirty[i] = sc->collided[i] ||
                                memcmp(x + 3 * i, sc->x_pass + 3 * i, 3 * sizeof *x) != 0;
        }
        memcpy(sc->x_pass, x, bytes);
        long found = pass == 0 && all_out_of_reach(sc, x)
                         ? 0
                         : find_collisions(sc, par, x, d->thickness, pass > 0),
             found_all = found;
        if (found < 0)
            abort(); /* out of memory finding collisions: no collision-free state to keep */
        memset(sc->collided, 0, (size_t)n);
        for (int l = 0; l < 2; l++) {
            const cs_pair_list *list = l ? &sc->cee : &sc->cpt;
            for (int j = 0; j < list->n; j++)
                for (int q = 0; q < 4; q++)
                    sc->collided[list->p[j].v[q]] = 1;
        }
        sc->stats.passes++;
        bool zone_mode = pass >= d->zone_iterations;
        for (int i = 0; i < n; i++)
            for (int c = 0; c < 3; c++)
                u[3 * i + c] = (x[3 * i + c] - sc->x_free[3 * i + c]) / span;
        cs_par_sum_long(par, &found_all, 1);
        if (pass == 0)
            first_pass = found_all;
        sc->stats.collisions += found;
        if (detect_only || found_all == 0)
            break;
        if (zone_mode) {
            if (merge_zones(sim) != 0)
                abort(); /* out of memory in the last resort: nothing safe to do */
            zones_formed++;
            if (!move_zones(sim, span, dv))
                break; /* the run stops: the state need not be collision free */
        } else {
            if (sc_distribute_boundary(sim, &sc->cpt, &sc->cee) != 0)
                abort();
            /* phase I: the state is synchronised; results go to the owners */
            respond_all(sc, &sc->bpt, &sc->bee, x, u, dv, span, &elastic);
            cs_halo_reverse(par, &sc->bhalo, x, 3);
            cs_halo_reverse(par, &sc->bhalo, u, 3);
            cs_halo_reverse(par, &sc->bhalo, dv, 3);
            /* phase II */
            respond_all(sc, &sc->cpt, &sc->cee, x, u, dv, span, &elastic);
        }
        if (pass > d->zone_iterations + 1000) {
            /* cannot happen in exact arithmetic for rigid zones (zones only
             * grow); a projected one may chase its collisions around. The
             * scripts cannot be followed where a zone spans two of them:
             * say so; else stop every particle at the collision-free state
             * rather than loop forever, the scripts too (their clocks
             * wait) */
            if (sc->stats.projected_zones > projected_before && sc->nkc > 0) {
                /* name a zone that spans scripts: the first constraint's
                 * zone may be a rigid one */
                int j = 0, count = 0;
                for (; j < sc->nkc; j++) {
                    count = zone_members(sc, sc_zone_find(sc->zone, sc->kc[j].v[0]));
                    if (zone_spans_scripts(sim, sc->zone_list, count))
                        break;
                }
                if (j == sc->nkc) /* none spans now: the first one, then */
                    count = zone_members(sc, sc_zone_find(sc->zone, sc->kc[j = 0].v[0]));
                memcpy(sc->conflict.where, x + 3 * sc->kc[j].v[3], sizeof sc->conflict.where);
                sc->conflict.shortfall = 0;
                note_conflict(sim, sc->zone_list, count);
                break;
            }
            memcpy(x, sc->x_free, bytes);
            for (int s = 0; s < sim->nscripts; s++)
                hold_script(sim, s, span);
            break;
        }
    }
    if (detect_only)
        return first_pass;
    if (zones_formed) {
        int roots = 0;
        for (int i = 0; i < n; i++)
            roots += sc->zone[i] >= 0 && sc_zone_find(sc->zone, i) == i;
        sc->stats.zones += roots;
    }
    CS_FOR_OWNED(par, i)
        for (int c = 0; c < 3; c++)
            sim->v[3 * i + c] += dv[3 * i + c];
    memcpy(sc->x_free, x, bytes); /* the same on every rank */
    sc->start_gap = 0;           /* measured in the old x_free */
    return first_pass;
}

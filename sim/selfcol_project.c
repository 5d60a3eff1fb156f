/* selfcol_project.c: step C's impact zones that hold vertices of two
 * prescribed motions (two scripts turning apart, a pin and a script).
 *
 * A rigid zone (the paper's, Bridson et al.'s) cannot follow two motions
 * at once. Prescribed vertices have infinite mass: they stay exactly where
 * their scripts put them, and the zone's free vertices are moved the least
 * (in the mass norm) that makes each collision found in the zone passes
 * hold, as a linear constraint on the span's end positions:
 *
 *   min  1/2 sum_i m_i |x_i - x_i*|^2   s.t.  n_j . sum_k c_jk x_k >= g_j
 *
 * with n_j and the weights c_j of collision j at its coplanar time, and
 * x* where the response passes left the zone. This is the inelastic
 * projection of Harmon, Vouga, Tamstorf and Grinspun (SIGGRAPH 2008),
 * taken at the level of positions with its gap, as ARCSim's impact zones
 * do (Narain et al. 2012), so that a pair is left apart rather than only
 * not approaching. Prescribed vertices simply carry no inverse mass. The
 * constraints grow pass by pass with what the next search finds, as the
 * zones do; a free zone stays rigid, as in the paper.
 *
 * The quadratic program is solved by Hildreth's method: Gauss-Seidel on
 * the dual, one collision at a time, each multiplier kept non-negative. A
 * step on collision j is the inelastic impulse that closes its shortfall,
 * the same arithmetic as step C's pair response, so a zone whose
 * collisions are independent is settled in one sweep; the method converges
 * to the program's optimum whenever one exists. A collision among
 * prescribed vertices only, or sweeps that run out, means no end state
 * follows the scripts: the caller stops the run and names the zone. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/selfcol_private.h"
#include "sim/vec3.h"

/* The gap a constraint asks for at the span's end: as far apart along n
 * as the pair started, but no more than this fraction of the repulsion
 * thickness (the repulsions of the next steps keep the rest), and never
 * below four times the proximity at which step C calls a pair colliding. */
#define ZONE_GAP_OF_THICKNESS 0.1
/* A constraint holds once it lacks at most this fraction of its gap: the
 * pair is then at least twice the proximity apart along its normal, which
 * step C's next search does not call a collision. Asking for more made a
 * tangled zone's sweeps crawl towards the last per cent of its gaps. */
#define ZONE_GAP_TOLERANCE 0.5
/* Hildreth sweeps over a zone's constraints before it is declared to have
 * no answer (its violations then grow without bound or stall). */
#define ZONE_MAX_SWEEPS 2000

int sc_zone_constraint_add(cs_selfcol *sc, const int v[4], const double c[4], const double n[3],
                           double thickness)
{
    if (sc->nkc == sc->kc_cap) {
        int cap = sc->kc_cap ? 2 * sc->kc_cap : 256;
        cs_zone_constraint *kc = realloc(sc->kc, sizeof *kc * (size_t)cap);
        int *list = realloc(sc->kc_list, sizeof *list * (size_t)cap);
        if (kc)
            sc->kc = kc;
        if (list)
            sc->kc_list = list;
        if (!kc || !list)
            return -1;
        sc->kc_cap = cap;
    }
    cs_zone_constraint *k = sc->kc + sc->nkc++;
    memcpy(k->v, v, sizeof k->v);
    memcpy(k->c, c, sizeof k->c);
    memcpy(k->n, n, sizeof k->n);
    double g0 = 0;
    for (int q = 0; q < 4; q++)
        g0 += c[q] * cs_dot(n, sc->x_free + 3 * v[q]);
    k->gap = fmax(fmin(g0, ZONE_GAP_OF_THICKNESS * thickness), 4 * sc->proximity);
    k->lambda = 0;
    return 0;
}

/* n . sum_k c_k x_k */
static double constraint_value(const cs_zone_constraint *k, const double *x)
{
    double g = 0;
    for (int q = 0; q < 4; q++)
        g += k->c[q] * cs_dot(k->n, x + 3 * k->v[q]);
    return g;
}

bool sc_project_zone(cs_selfcol *sc, int root, double *x, cs_script_conflict *why)
{
    int m = 0;
    for (int j = 0; j < sc->nkc; j++)
        if (sc_zone_find(sc->zone, sc->kc[j].v[0]) == root) {
            sc->kc[j].lambda = 0;
            sc->kc_list[m++] = j;
        }
    const cs_zone_constraint *worst = NULL;
    double worst_short = 0;
    for (int sweep = 0; sweep < ZONE_MAX_SWEEPS; sweep++) {
        worst = NULL;
        worst_short = 0;
        bool moved = false; /* a multiplier let go of more than the tolerance */
        for (int l = 0; l < m; l++) {
            cs_zone_constraint *k = sc->kc + sc->kc_list[l];
            double shortfall = k->gap - constraint_value(k, x);
            if (shortfall > ZONE_GAP_TOLERANCE * k->gap && shortfall > worst_short) {
                worst = k;
                worst_short = shortfall;
            }
            if (shortfall <= 0 && k->lambda == 0)
                continue;
            double w = 0;
            for (int q = 0; q < 4; q++)
                w += k->c[q] * k->c[q] * sc->inv_mass[k->v[q]];
            if (!(w > 0)) {
                if (shortfall > ZONE_GAP_TOLERANCE * k->gap) {
                    /* prescribed vertices only: nothing can move */
                    worst = k;
                    worst_short = shortfall;
                    sweep = ZONE_MAX_SWEEPS;
                    break;
                }
                continue;
            }
            double dl = fmax(-k->lambda, shortfall / w);
            k->lambda += dl;
            moved = moved || -dl * w > ZONE_GAP_TOLERANCE * k->gap;
            for (int q = 0; q < 4; q++)
                cs_axpy(dl * k->c[q] * sc->inv_mass[k->v[q]], k->n, x + 3 * k->v[q]);
        }
        if (!worst && !moved)
            return true;
    }
    why->shortfall = worst_short;
    if (worst)
        memcpy(why->where, x + 3 * worst->v[3], sizeof why->where);
    return false;
}

/* "cloth 'sheet' script 1" for script s (numbered across the cloths). */
static void name_script(const cs_sim *sim, int s, char *buf, size_t len)
{
    if (s < 0) {
        snprintf(buf, len, "pins");
        return;
    }
    /* scripts are numbered cloth by cloth: the cloth of its vertices, and
     * how many scripts of that cloth come before it */
    int c = 0, g = sim->scripts[s].nvertices > 0 ? sim->scripts[s].vertices[0] : -1;
    while (c + 1 < sim->ncloths && g >= sim->cloths[c + 1].offset)
        c++;
    /* the importer makes a cloth's pins its first script, a static one */
    int first = -1, within = 0;
    for (int t = 0; t < sim->nscripts; t++)
        if (sim->scripts[t].nvertices > 0 && sim->scripts[t].vertices[0] >= sim->cloths[c].offset &&
            (c + 1 >= sim->ncloths || sim->scripts[t].vertices[0] < sim->cloths[c + 1].offset)) {
            if (first < 0)
                first = t;
            within += t < s;
        }
    bool pins = first >= 0 && sim->scripts[first].motion.kind == CS_MOTION_STATIC;
    if (g >= 0) {
        const char *name = sim->cloths[c].name;
        if (pins && s == first)
            snprintf(buf, len, "cloths.%d (%s) pins", c, name ? name : "unnamed");
        else
            snprintf(buf, len, "cloths.%d (%s) scripts.%d", c, name ? name : "unnamed",
                     within - pins);
        return;
    }
    snprintf(buf, len, "script %d", s);
}

bool cs_sim_script_conflict(const cs_sim *sim, char *buf, size_t len)
{
    const cs_script_conflict *why = sim->selfcol ? &sim->selfcol->conflict : NULL;
    if (!why || !why->found)
        return false;
    char names[512] = "";
    for (int k = 0; k < why->nscripts; k++) {
        char one[160];
        name_script(sim, why->scripts[k], one, sizeof one);
        size_t used = strlen(names);
        snprintf(names + used, sizeof names - used, "%s%s", k ? " and " : "", one);
    }
    char shortfall[96] = "";
    if (why->shortfall > 0)
        snprintf(shortfall, sizeof shortfall, " (a collision %.3g m short of its gap)",
                 why->shortfall);
    snprintf(buf, len,
             "no collision-free state follows the scripts at t=%.6g s: an impact zone of %d "
             "vertices near (%.4g, %.4g, %.4g) holds %s%s, which move through each other or "
             "pinch the cloth%s; set self_collision.script_zones: hold to let the scripts wait",
             why->t, why->zone_size, why->where[0], why->where[1], why->where[2], names,
             why->more_scripts ? " and more" : "", shortfall);
    return true;
}

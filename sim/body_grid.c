/* body_grid.c: the uniform partition of body occupancy (see body_grid.h).
 *
 * The cells cover the union of the bounded bodies' boxes, about eight per
 * body (at most 128 along an axis), so a body of typical size overlaps a
 * few cells and a point looks at the few bodies of its own cell. Building
 * is O(bodies x cells each + points), done per step because bodies and
 * points move; it is small next to the phi queries it saves. */
#include "sim/body_grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_DIM 128
/* cells aimed at: a few per bounded body, so a body's box covers few cells
 * and a cell few bodies (the query visits each body once anyway) */
enum { CELLS_PER_BODY = 8, MIN_CELLS = 64 };

static int clampi(int v, int lo, int hi) { return v < lo ? lo : v > hi ? hi : v; }

static int cell_coord(const cs_body_grid *g, int k, double v)
{
    double s = (v - g->origin[k]) * g->inv_cell[k];
    if (!(s > 0))
        return 0;
    if (s >= g->dim[k])
        return g->dim[k] - 1;
    return (int)s;
}

static bool in_box(const double *lo, const double *hi, const double p[3])
{
    return p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && p[2] >= lo[2] &&
           p[2] <= hi[2];
}

bool cs_body_grid_inside(const cs_body_grid *g, int b, const double p[3])
{
    return g->ok && g->bounded[b] && in_box(g->lo + 3 * b, g->hi + 3 * b, p);
}

void cs_body_grid_cell_bodies(const cs_body_grid *g, const double p[3], int *first, int *last)
{
    *first = *last = 0;
    if (!g->ok || !g->cell_start || !in_box(g->ulo, g->uhi, p))
        return;
    int c = (cell_coord(g, 2, p[2]) * g->dim[1] + cell_coord(g, 1, p[1])) * g->dim[0] +
            cell_coord(g, 0, p[0]);
    *first = g->cell_start[c];
    *last = g->cell_start[c + 1];
}

void cs_body_grid_free(cs_body_grid *g)
{
    free(g->bounded);
    free(g->lo);
    free(g->hi);
    free(g->cell_start);
    free(g->cell_bodies);
    free(g->start);
    free(g->points);
    memset(g, 0, sizeof *g);
}

/* Cells of the union box; false when memory runs out. */
static bool build_cells(cs_body_grid *g, int nbounded)
{
    double ext[3], vol = 1, maxext = 0;
    for (int k = 0; k < 3; k++) {
        ext[k] = g->uhi[k] - g->ulo[k];
        maxext = fmax(maxext, ext[k]);
    }
    double target = fmax(MIN_CELLS, (double)CELLS_PER_BODY * nbounded);
    for (int k = 0; k < 3; k++)
        vol *= fmax(ext[k], maxext / MAX_DIM);
    double cell = fmax(cbrt(vol / target), maxext / MAX_DIM);
    long ncells = 1;
    for (int k = 0; k < 3; k++) {
        g->origin[k] = g->ulo[k];
        g->dim[k] = cell > 0 ? clampi((int)ceil(ext[k] / cell), 1, MAX_DIM) : 1;
        g->inv_cell[k] = ext[k] > 0 ? g->dim[k] / ext[k] : 0;
        ncells *= g->dim[k];
    }
    g->cell_start = calloc((size_t)ncells + 1, sizeof *g->cell_start);
    if (!g->cell_start)
        return false;
    /* count, prefix-sum, fill: bodies stay ascending within a cell */
    for (int pass = 0; pass < 2; pass++) {
        for (int b = 0; b < g->nbodies; b++) {
            if (!g->bounded[b])
                continue;
            int c0[3], c1[3];
            for (int k = 0; k < 3; k++) {
                c0[k] = cell_coord(g, k, g->lo[3 * b + k]);
                c1[k] = cell_coord(g, k, g->hi[3 * b + k]);
            }
            for (int z = c0[2]; z <= c1[2]; z++)
                for (int y = c0[1]; y <= c1[1]; y++)
                    for (int x = c0[0]; x <= c1[0]; x++) {
                        int c = (z * g->dim[1] + y) * g->dim[0] + x;
                        if (pass == 0)
                            g->cell_start[c + 1]++;
                        else
                            g->cell_bodies[g->cell_start[c]++] = b;
                    }
        }
        if (pass == 0) {
            for (long c = 0; c < ncells; c++)
                g->cell_start[c + 1] += g->cell_start[c];
            g->cell_bodies = malloc(((size_t)g->cell_start[ncells] + 1) * sizeof *g->cell_bodies);
            if (!g->cell_bodies)
                return false;
        } else { /* the fill advanced each start to the next cell's: shift back */
            for (long c = ncells; c > 0; c--)
                g->cell_start[c] = g->cell_start[c - 1];
            g->cell_start[0] = 0;
        }
    }
    return true;
}

void cs_body_grid_build(cs_body_grid *g, const cs_body_def *bodies, int nbodies, double t,
                        const double *x, const unsigned char *is_free, int n)
{
    memset(g, 0, sizeof *g);
    g->nbodies = nbodies;
    g->bounded = calloc((size_t)nbodies + 1, 1);
    g->lo = malloc(3 * ((size_t)nbodies + 1) * sizeof *g->lo);
    g->hi = malloc(3 * ((size_t)nbodies + 1) * sizeof *g->hi);
    g->start = calloc((size_t)nbodies + 1, sizeof *g->start);
    if (!g->bounded || !g->lo || !g->hi || !g->start)
        goto fail;
    int nbounded = 0;
    for (int k = 0; k < 3; k++) {
        g->ulo[k] = INFINITY;
        g->uhi[k] = -INFINITY;
    }
    for (int b = 0; b < nbodies; b++) {
        double *lo = g->lo + 3 * b, *hi = g->hi + 3 * b;
        bool finite = cs_body_def_bounds(bodies + b, t, lo, hi);
        for (int k = 0; k < 3 && finite; k++)
            finite = isfinite(lo[k]) && isfinite(hi[k]);
        if (!finite)
            continue;
        g->bounded[b] = 1;
        nbounded++;
        for (int k = 0; k < 3; k++) {
            g->ulo[k] = fmin(g->ulo[k], lo[k]);
            g->uhi[k] = fmax(g->uhi[k], hi[k]);
        }
    }
    g->ok = true;
    if (nbounded == 0)
        return;
    if (!build_cells(g, nbounded))
        goto fail;
    if (!x)
        return; /* the cells only */

    /* candidates: count per body, prefix-sum, fill in point order */
    int *count = calloc((size_t)nbodies + 1, sizeof *count);
    if (!count)
        goto fail;
    for (int pass = 0; pass < 2; pass++) {
        for (int i = 0; i < n; i++) {
            if (!is_free[i])
                continue;
            const double *p = x + 3 * i;
            int first, last;
            cs_body_grid_cell_bodies(g, p, &first, &last);
            for (int j = first; j < last; j++) {
                int b = g->cell_bodies[j];
                if (!in_box(g->lo + 3 * b, g->hi + 3 * b, p))
                    continue;
                if (pass == 0)
                    count[b]++;
                else
                    g->points[g->start[b] + count[b]++] = i;
            }
        }
        if (pass == 0) {
            g->start[0] = 0;
            for (int b = 0; b < nbodies; b++)
                g->start[b + 1] = g->start[b] + count[b];
            g->points = malloc(((size_t)g->start[nbodies] + 1) * sizeof *g->points);
            memset(count, 0, ((size_t)nbodies + 1) * sizeof *count);
            if (!g->points) {
                free(count);
                goto fail;
            }
        }
    }
    free(count);
    return;
fail:
    cs_body_grid_free(g);
    g->nbodies = nbodies;
    g->ok = false;
}

/* resample.c: values given on one mesh's vertices carried to another
 * mesh's vertices through their rest shapes (cs_surface_map, sim.h).
 *
 * Each target vertex takes the point of the source mesh's surface nearest
 * its own rest position: a source triangle and barycentric weights, the
 * values then interpolated linearly. Where the two meshes are the same
 * surface sampled at two resolutions (a grid of 200 x 50 quads and one of
 * 1000 x 250 over the same rectangle) every target vertex lies on the
 * source surface and the map is the source's piecewise-linear shape
 * exactly: a collision-free source state stays collision-free wherever the
 * target's triangles lie inside the source's, and is changed by at most
 * the chord of a source crease elsewhere (the caller counts the
 * intersections of the result).
 *
 * The nearest triangle comes from a uniform grid of the source triangles'
 * boxes (cells about two mean edges wide), searched in rings of cells
 * around the target vertex until no nearer triangle can lie further out.
 * The triangles of a cell are tried in index order and a triangle replaces
 * the best only when strictly nearer, so the map does not depend on the
 * thread count. */
#include <math.h>
#include <stdlib.h>

#include "sim/ccd.h"
#include "sim/sim.h"

struct cs_surface_map {
    int nv;        /* target vertices */
    int *tri;      /* per target vertex: the source triangle */
    double *w;     /* per target vertex: 3 barycentric weights */
};

typedef struct tri_grid {
    double lo[3], cell;
    int dim[3];
    int *start;    /* dim[0] dim[1] dim[2] + 1 offsets into items */
    int *items;    /* triangle indices, by cell, ascending */
} tri_grid;

/* the grid is at most this many cells in all, whatever the mesh's spread */
enum { MAX_CELLS = 1 << 22 };

static int cell_of(const tri_grid *g, double x, int d)
{
    double c = floor((x - g->lo[d]) / g->cell);
    return c < 0 ? 0 : c >= g->dim[d] ? g->dim[d] - 1 : (int)c;
}

static void tri_box(const cs_trimesh *m, int t, double lo[3], double hi[3])
{
    for (int d = 0; d < 3; d++) {
        lo[d] = INFINITY;
        hi[d] = -INFINITY;
        for (int k = 0; k < 3; k++) {
            double x = m->x[3 * m->tri[3 * t + k] + d];
            lo[d] = fmin(lo[d], x);
            hi[d] = fmax(hi[d], x);
        }
    }
}

/* Two passes over the triangles: count each cell's, then fill. */
static int grid_build(tri_grid *g, const cs_trimesh *m)
{
    double hi[3];
    for (int d = 0; d < 3; d++) {
        g->lo[d] = INFINITY;
        hi[d] = -INFINITY;
    }
    for (int i = 0; i < m->nv; i++)
        for (int d = 0; d < 3; d++) {
            g->lo[d] = fmin(g->lo[d], m->x[3 * i + d]);
            hi[d] = fmax(hi[d], m->x[3 * i + d]);
        }
    double extent = fmax(hi[0] - g->lo[0], fmax(hi[1] - g->lo[1], hi[2] - g->lo[2]));
    g->cell = 2 * cs_trimesh_mean_edge(m);
    if (!(g->cell > 0))
        g->cell = extent > 0 ? extent : 1;
    for (;;) {
        double cells = 1;
        for (int d = 0; d < 3; d++) {
            g->dim[d] = 1 + (int)fmin((hi[d] - g->lo[d]) / g->cell, MAX_CELLS);
            cells *= g->dim[d];
        }
        if (cells <= MAX_CELLS)
            break;
        g->cell *= 2;
    }
    size_t ncells = (size_t)g->dim[0] * g->dim[1] * g->dim[2];
    g->start = calloc(ncells + 2, sizeof *g->start);
    if (!g->start)
        return -1;
    /* pass 1 counts into start[cell + 2], so that after the prefix sum
     * start[cell + 1] is where the cell's items begin while filling */
    for (int pass = 0; pass < 2; pass++) {
        for (int t = 0; t < m->nt; t++) {
            double blo[3], bhi[3];
            tri_box(m, t, blo, bhi);
            int c0[3], c1[3];
            for (int d = 0; d < 3; d++) {
                c0[d] = cell_of(g, blo[d], d);
                c1[d] = cell_of(g, bhi[d], d);
            }
            for (int k = c0[2]; k <= c1[2]; k++)
                for (int j = c0[1]; j <= c1[1]; j++)
                    for (int i = c0[0]; i <= c1[0]; i++) {
                        size_t c = ((size_t)k * g->dim[1] + j) * g->dim[0] + i;
                        if (pass == 0)
                            g->start[c + 2]++;
                        else
                            g->items[g->start[c + 1]++] = t;
                    }
        }
        if (pass == 0) {
            for (size_t c = 2; c < ncells + 2; c++)
                g->start[c] += g->start[c - 1];
            g->items = malloc(sizeof *g->items * ((size_t)g->start[ncells + 1] + 1));
            if (!g->items)
                return -1;
        }
    }
    return 0;
}

/* The nearest source triangle to p and its weights; returns the distance. */
static double nearest(const tri_grid *g, const cs_trimesh *m, const double p[3], int *best_tri,
                      double best_w[3])
{
    int c[3];
    for (int d = 0; d < 3; d++)
        c[d] = cell_of(g, p[d], d);
    int maxring = g->dim[0] + g->dim[1] + g->dim[2];
    double best = INFINITY;
    *best_tri = -1;
    for (int r = 0; r <= maxring; r++) {
        for (int k = c[2] - r; k <= c[2] + r; k++)
            for (int j = c[1] - r; j <= c[1] + r; j++)
                for (int i = c[0] - r; i <= c[0] + r; i++) {
                    /* only the shell of ring r: the inside was searched */
                    if (abs(i - c[0]) != r && abs(j - c[1]) != r && abs(k - c[2]) != r)
                        continue;
                    if (i < 0 || j < 0 || k < 0 || i >= g->dim[0] || j >= g->dim[1] ||
                        k >= g->dim[2])
                        continue;
                    size_t cell = ((size_t)k * g->dim[1] + j) * g->dim[0] + i;
                    for (int q = g->start[cell]; q < g->start[cell + 1]; q++) {
                        int t = g->items[q];
                        double w[3];
                        const int *v = m->tri + 3 * t;
                        double dist = cs_point_triangle_closest(p, m->x + 3 * v[0], m->x + 3 * v[1],
                                                                m->x + 3 * v[2], w);
                        if (dist < best || (dist == best && t < *best_tri)) {
                            best = dist;
                            *best_tri = t;
                            best_w[0] = w[0], best_w[1] = w[1], best_w[2] = w[2];
                        }
                    }
                }
        /* anything outside ring r is at least r cells away from p's cell */
        if (*best_tri >= 0 && best <= r * g->cell)
            break;
    }
    return best;
}

cs_surface_map *cs_surface_map_create(const cs_trimesh *from, const cs_trimesh *to,
                                      double *worst)
{
    *worst = INFINITY;
    if (!from || !to || from->nt < 1)
        return NULL;
    cs_surface_map *map = calloc(1, sizeof *map);
    tri_grid g = {0};
    if (!map || grid_build(&g, from) != 0) {
        free(g.start);
        free(g.items);
        free(map);
        return NULL;
    }
    map->nv = to->nv;
    map->tri = malloc(sizeof *map->tri * ((size_t)to->nv + 1));
    map->w = malloc(sizeof *map->w * 3 * ((size_t)to->nv + 1));
    double far = 0;
    if (map->tri && map->w) {
#pragma omp parallel for schedule(static) reduction(max : far)
        for (int i = 0; i < to->nv; i++) {
            double d = nearest(&g, from, to->x + 3 * i, map->tri + i, map->w + 3 * i);
            far = fmax(far, d);
        }
    }
    free(g.start);
    free(g.items);
    if (!map->tri || !map->w) {
        cs_surface_map_destroy(map);
        return NULL;
    }
    *worst = far;
    return map;
}

void cs_surface_map_apply(const cs_surface_map *map, const cs_trimesh *from,
                          const double *from_values, double *to_values)
{
#pragma omp parallel for schedule(static)
    for (int i = 0; i < map->nv; i++) {
        const int *v = from->tri + 3 * map->tri[i];
        const double *w = map->w + 3 * i;
        for (int d = 0; d < 3; d++)
            to_values[3 * i + d] = w[0] * from_values[3 * v[0] + d] +
                                   w[1] * from_values[3 * v[1] + d] +
                                   w[2] * from_values[3 * v[2] + d];
    }
}

void cs_surface_map_destroy(cs_surface_map *map)
{
    if (!map)
        return;
    free(map->tri);
    free(map->w);
    free(map);
}

/* body_grid.h: private to sim/. A uniform spatial partition of body
 * occupancy, rebuilt for the bodies' pose at each step: every bounded body
 * gets the list of free cloth points inside its world box, so that B.4
 * visits each body once with the few points that may touch it instead of
 * asking every body about every point. Unbounded bodies (planes) are asked
 * about every free point. */
#ifndef CS_BODY_GRID_H
#define CS_BODY_GRID_H

#include <stdbool.h>

#include "sim/sim.h"

typedef struct cs_body_grid {
    int nbodies;
    bool ok;                   /* false: built nothing (no memory); treat
                                  every body as unbounded */
    unsigned char *bounded;    /* per body */
    double *lo, *hi;           /* 3 per body: world boxes */
    /* the cells: a uniform grid over the union of the bounded boxes */
    double origin[3], inv_cell[3];
    int dim[3];
    double ulo[3], uhi[3];     /* the union */
    int *cell_start;           /* ncells + 1 */
    int *cell_bodies;          /* bounded bodies overlapping each cell, ascending */
    /* candidates: points of body b are points[start[b] .. start[b+1]) */
    int *start;
    int *points;
} cs_body_grid;

/* body_bounds.c: a world box at time t holding every point where the
 * body's phi < offset (the region where it collides). False for an
 * unbounded body (a plane, or phi_fn without phi_bounded). */
bool cs_body_def_bounds(const cs_body_def *b, double t, double lo[3], double hi[3]);

/* Builds the partition for the bodies at time t and points x (3 per point);
 * only points with is_free[i] are listed. With x NULL, only the cells (for
 * cs_body_grid_cell_bodies): no point is listed. */
void cs_body_grid_build(cs_body_grid *g, const cs_body_def *bodies, int nbodies, double t,
                        const double *x, const unsigned char *is_free, int n);
void cs_body_grid_free(cs_body_grid *g);

/* Whether point p lies in body b's box (false for unbounded bodies). */
bool cs_body_grid_inside(const cs_body_grid *g, int b, const double p[3]);

/* The bounded bodies whose cells hold p: [*first, *last) of cell_bodies;
 * an empty range when p is outside every box's cell. */
void cs_body_grid_cell_bodies(const cs_body_grid *g, const double p[3], int *first, int *last);

#endif

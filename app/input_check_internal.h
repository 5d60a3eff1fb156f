/* input_check_internal.h: what the parts of the initial-state check share:
 * all cloth as one mesh and the findings by kind (input_check.c builds and
 * analyses it), their listing and the verdict at the start of `run`
 * (input_report.c), --fix (input_fix.c), and the `clothsim check` command
 * (check_cmd.c). */
#ifndef CS_APP_INPUT_CHECK_INTERNAL_H
#define CS_APP_INPUT_CHECK_INTERNAL_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "import/import.h"

#define LIST_MAX 20          /* findings listed per kind */

enum kind {
    K_CROSS,       /* triangles of two cloths intersect */
    K_SELF,        /* triangles of one cloth intersect */
    K_BODY_IN,     /* a vertex inside a body */
    K_BODY_EDGE,   /* an edge through a body, both ends outside */
    K_BODY_NEAR,   /* a vertex outside a body but closer than the threshold */
    K_SELF_NEAR,   /* a vertex closer than the thickness to a triangle not its own */
    K_DEGEN,       /* a triangle of (near) zero area */
    K_NONMANIFOLD, /* an edge in more than two triangles */
    K_COUNT
};

typedef struct finding {
    int cloth, a;    /* cloth and its triangle (pairs, degenerate), vertex or edge end */
    int cloth2, b;   /* the other triangle, or the edge's other end; -1 if none */
    int body;        /* the body, or -1 */
    double pos[3];   /* where, world */
    double value;    /* depth, distance, area or triangle count */
} finding;

typedef struct kind_list {
    long count;
    int n;
    finding first[LIST_MAX];
} kind_list;

typedef struct report {
    kind_list k[K_COUNT];
    long verifier_pairs; /* cs_find_intersections' count, all cloths as one mesh */
    bool self_checked;   /* closeness to itself looked at (self-collision on) */
    bool bodies_checked; /* bodies looked at (effects.bodies on, bodies present) */
    double thickness;
} report;

/* All cloth as one mesh, in particle order. */
typedef struct cloth_set {
    const cs_scene *scene;
    int ncloths, nv, nt;
    int *voff, *toff;   /* per cloth: first vertex and first triangle; [ncloths]: totals */
    double *x;
    int *tri;           /* global vertex indices */
    int *tcloth;        /* per triangle its cloth */
    int *vcloth;        /* per vertex its cloth */
} cloth_set;

int cs_cloth_set_init(cloth_set *s, const cs_scene *scene);
void cs_cloth_set_free(cloth_set *s);
/* Cloth c's name, "?" without one. */
const char *cs_cloth_set_name(const cloth_set *s, int c);

/* Every check the scene asks for, into r (zeroed first). Returns 0, or -1
 * when memory runs out. */
int cs_input_analyse(const cloth_set *s, report *r);

/* The findings that `run` refuses. */
long cs_input_errors(const report *r);
/* The findings of every kind, errors first: a count and the first 20, each
 * line after prefix. */
void cs_input_print_report(FILE *out, const cloth_set *s, const report *r, const char *prefix);

typedef struct fix_result {
    long moved;        /* vertices moved */
    long stuck;        /* vertices still inside or too close after the fix */
    double max_move;   /* m */
} fix_result;

/* Moves the vertices closer to a body than the threshold out (s->x), and
 * says how many and how far in fr. */
void cs_input_fix_bodies(cloth_set *s, fix_result *fr);
/* The fixed cloths into dir: NAME.ply each and cloths.yaml. Returns 0, or
 * -1 with err. */
int cs_input_write_fixed(const cloth_set *s, const char *dir, char *err, size_t errlen);

static inline bool cs_input_bodies_on(const cs_scene *scene)
{
    return scene->def.bodies_enabled && scene->def.nbodies > 0;
}

/* The distance below which a vertex is too close to body b. */
static inline double cs_input_body_threshold(const cs_scene *scene, int b)
{
    return fmax(scene->def.self.thickness, scene->def.bodies[b].offset);
}

static inline double cs_dist3(const double *a, const double *b)
{
    double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

#endif

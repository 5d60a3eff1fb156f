/* usd_write.h: USD's text format (.usda) written as a stream, for
 * cloth.usda (app/export.c): the stage's metadata, one root Xform, meshes
 * (topology once, points as a default value or as time samples) and
 * rigid transforms. Every call appends to a FILE; nothing is held, so a
 * prim's time samples can be written (or copied) one frame at a time.
 * Errors show in the FILE (ferror), which the caller checks once.
 *
 * Floats are written to round-trip: point3f and color3f with %.9g of the
 * float32 value, matrix4d with %.17g. */
#ifndef CS_APP_USD_WRITE_H
#define CS_APP_USD_WRITE_H

#include <stdio.h>

typedef struct cs_usd_stage {
    const char *root;     /* the root prim and defaultPrim: an identifier */
    const char *up_axis;  /* "Y" or "Z" */
    double fps;           /* timeCodesPerSecond and framesPerSecond */
    int start, end;       /* startTimeCode, endTimeCode */
} cs_usd_stage;

/* name made a prim name (an identifier: ASCII letters, digits and '_', not
 * starting with a digit; every other byte '_', a leading digit preceded by
 * '_', an empty name fallback) and different from taken[0 .. ntaken), by
 * a suffix _2, _3, ... into out (len >= 32). */
void cs_usd_identifier(const char *name, const char *fallback, const char *const *taken,
                       int ntaken, char *out, size_t len);

/* The header, the stage metadata and `def Xform "ROOT" {`. */
void cs_usd_begin_stage(FILE *fp, const cs_usd_stage *stage);
/* Closes the root prim. */
void cs_usd_end_stage(FILE *fp);

/* `def Mesh "PRIM" {` with its triangles (faceVertexCounts,
 * faceVertexIndices), subdivisionScheme none, primvars:displayColor
 * (linear RGB) and the name as given (custom string clothsim:name),
 * quoted. */
void cs_usd_begin_mesh(FILE *fp, const char *prim, const char *name, int nt, const int *tri,
                       const double color[3]);
void cs_usd_end_mesh(FILE *fp);

/* `point3f[] points = [...]`: positions that do not change. */
void cs_usd_points(FILE *fp, int nv, const double *x);

/* One time sample of points, `CODE: [(x, y, z), ...],`, as the lines
 * between cs_usd_begin_points_samples and cs_usd_end_samples. */
void cs_usd_begin_points_samples(FILE *fp);
void cs_usd_points_sample(FILE *fp, int code, int nv, const float *x);
void cs_usd_end_samples(FILE *fp);

/* The rigid transform p -> R p + c (R row-major) of a prim: a default value
 * (cs_usd_transform) or time samples (begin, sample..., end), and then
 * cs_usd_transform_order once. */
void cs_usd_transform(FILE *fp, const double R[9], const double c[3]);
void cs_usd_begin_transform_samples(FILE *fp);
void cs_usd_transform_sample(FILE *fp, int code, const double R[9], const double c[3]);
void cs_usd_transform_order(FILE *fp);

#endif

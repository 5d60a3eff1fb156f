/* pc2_write.h: Blender's point cache, PC2, written as a stream, with the
 * rest-pose OBJ the Mesh Cache modifier is put on (app/export.c).
 *
 * PC2: the 12 bytes "POINTCACHE2\0", int32 version 1, int32 points,
 * float32 start frame, float32 sample rate, int32 samples, then per sample
 * per point three float32 (x, y, z); all little-endian. The file is
 * written as PATH.tmp, the sample count patched in at the end, then
 * renamed, so PATH is always whole. */
#ifndef CS_APP_PC2_WRITE_H
#define CS_APP_PC2_WRITE_H

#include <stddef.h>
#include <stdio.h>

typedef struct cs_pc2 {
    FILE *fp;
    char *path, *tmp;
    int npoints;
    int nsamples;
} cs_pc2;

/* Starts path.tmp with the header (no samples yet). Returns 0, or -1 with
 * err. */
int cs_pc2_open(cs_pc2 *p, const char *path, int npoints, float start, float rate, char *err,
                size_t errlen);
/* Appends one sample: npoints x, y, z. Write errors show at cs_pc2_close. */
void cs_pc2_add(cs_pc2 *p, const float *xyz);
/* Patches the sample count, closes and renames. Returns 0, or -1 with err
 * and the temporary file removed. */
int cs_pc2_close(cs_pc2 *p, char *err, size_t errlen);
/* Closes and removes the temporary file (after another failure). */
void cs_pc2_abandon(cs_pc2 *p);

/* The rest pose as an OBJ, atomically: `o NAME`, a `v` line per point
 * (%.9g of the float32 values, so it reads back as the same floats) and an
 * `f` line per triangle, in the order given (the cache's point order).
 * Returns 0, or -1 with err. */
int cs_rest_obj_write(const char *path, const char *name, int nv, const float *x, int nt,
                      const int *tri, char *err, size_t errlen);

#endif

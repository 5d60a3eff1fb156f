/* pc2_write.c: Blender's PC2 point cache and its rest-pose OBJ
 * (pc2_write.h). */
#include "app/pc2_write.h"

#include "common/util.h"

#include <errno.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ PC2 */

static void put_u32(FILE *fp, uint32_t v)
{
    unsigned char le[4] = {v & 0xFF, (v >> 8) & 0xFF, (v >> 16) & 0xFF, v >> 24};
    fwrite(le, 1, sizeof le, fp);
}

static void put_f32(FILE *fp, float f)
{
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    put_u32(fp, bits);
}

#define PC2_SAMPLES_OFFSET 28 /* signature 12, version, points, start, rate */

int cs_pc2_open(cs_pc2 *p, const char *path, int npoints, float start, float rate, char *err,
                size_t errlen)
{
    memset(p, 0, sizeof *p);
    p->npoints = npoints;
    p->path = strdup(path);
    p->tmp = cs_path_tmp(path);
    if (!p->path || !p->tmp) {
        cs_errorf(err, errlen, "cannot write %s: out of memory", path);
        cs_pc2_abandon(p);
        return -1;
    }
    if (!(p->fp = fopen(p->tmp, "wb"))) {
        cs_errorf(err, errlen, "cannot write %s: %s", p->tmp, strerror(errno));
        cs_pc2_abandon(p);
        return -1;
    }
    fwrite("POINTCACHE2", 1, 12, p->fp); /* with its NUL */
    put_u32(p->fp, 1);
    put_u32(p->fp, (uint32_t)npoints);
    put_f32(p->fp, start);
    put_f32(p->fp, rate);
    put_u32(p->fp, 0); /* the samples: patched by cs_pc2_close */
    return 0;
}

void cs_pc2_add(cs_pc2 *p, const float *xyz)
{
    for (int i = 0; i < 3 * p->npoints; i++)
        put_f32(p->fp, xyz[i]);
    p->nsamples++;
}

static void pc2_free(cs_pc2 *p)
{
    free(p->path);
    free(p->tmp);
    p->path = p->tmp = NULL;
    p->fp = NULL;
}

int cs_pc2_close(cs_pc2 *p, char *err, size_t errlen)
{
    char why[256] = "";
    errno = 0;
    /* the count goes where the header left room for it */
    if (fflush(p->fp) == 0 && fseek(p->fp, PC2_SAMPLES_OFFSET, SEEK_SET) == 0)
        put_u32(p->fp, (uint32_t)p->nsamples);
    else if (!ferror(p->fp))
        snprintf(why, sizeof why, "%s", strerror(errno ? errno : EIO));
    bool failed = cs_file_close_checked(p->fp, why[0] ? NULL : why, sizeof why) != 0 || why[0];
    p->fp = NULL;
    if (!failed && rename(p->tmp, p->path) != 0) {
        snprintf(why, sizeof why, "%s", strerror(errno));
        failed = true;
    }
    if (failed) {
        cs_errorf(err, errlen, "cannot write %s: %s", p->path, why);
        remove(p->tmp);
    }
    pc2_free(p);
    return failed ? -1 : 0;
}

void cs_pc2_abandon(cs_pc2 *p)
{
    if (p->fp) {
        fclose(p->fp);
        remove(p->tmp);
    }
    pc2_free(p);
}

/* -------------------------------------------------------- the rest pose */

typedef struct rest_obj {
    const char *name;
    int nv, nt;
    const float *x;
    const int *tri;
} rest_obj;

static int fill_obj(const char *tmp, void *ctx, char *why, size_t whylen)
{
    const rest_obj *o = ctx;
    FILE *fp = cs_file_open_checked(tmp, "w", why, whylen);
    if (!fp)
        return -1;
    fprintf(fp, "# clothsim: rest pose (frame 0) of a PC2 point cache, %d points\no %s\n", o->nv,
            o->name);
    for (int v = 0; v < o->nv; v++)
        fprintf(fp, "v %.9g %.9g %.9g\n", (double)o->x[3 * v], (double)o->x[3 * v + 1],
                (double)o->x[3 * v + 2]);
    for (int t = 0; t < o->nt; t++)
        fprintf(fp, "f %d %d %d\n", o->tri[3 * t] + 1, o->tri[3 * t + 1] + 1,
                o->tri[3 * t + 2] + 1);
    return cs_file_close_checked(fp, why, whylen);
}

int cs_rest_obj_write(const char *path, const char *name, int nv, const float *x, int nt,
                      const int *tri, char *err, size_t errlen)
{
    rest_obj o = {name, nv, nt, x, tri};
    return cs_write_atomic(path, false, fill_obj, &o, err, errlen);
}

/* levelset_build.c: mesh bodies become grids: choosing and checking the
 * voxel size, and the cache of converted grids.
 *
 * The cache holds .vdb files, which other tools open (OpenVDB's vdb_print,
 * Houdini, Blender). A file is named <label>-<first 16 hex digits of the
 * key>.vdb and carries the whole key as grid metadata "clothsim_key"; the
 * key is the XXH3-128 hash of the mesh as OpenVDB receives it (32-bit float
 * coordinates after placement and repairs, triangle indices), the voxel
 * size, band, interior fill and the OpenVDB version. So a grid is reused
 * exactly when it would come out the same, whatever the files' times. */
#include "import/import.h"

#include "common/util.h"


#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

/* ------------------------------------------------------------ sizes */

/* Peak memory of a conversion, from bench/levelset_speed.c with OpenVDB 10:
 * about 46 bytes per narrow-band voxel (the grid keeps 13 of them; the rest
 * is the conversion's own trees) and 12 per voxel of a filled interior,
 * whose leaves are dense. With some margin: */
#define BAND_PEAK_BYTES 52.0
#define FILL_PEAK_BYTES 16.0

static double band_voxels(const cs_mesh_report *m, double voxel, double band, bool fill)
{
    /* outside band and the surface layer, and the inside band unless filled */
    return m->area / (voxel * voxel) * (band + 1.0 + (fill ? 0.0 : band));
}

static double fill_voxels(const cs_mesh_report *m, double voxel, bool fill)
{
    return fill ? m->volume / (voxel * voxel * voxel) : 0.0;
}

double cs_levelset_estimate_voxels(const cs_mesh_report *m, double voxel, double band,
                                   bool fill)
{
    return band_voxels(m, voxel, band, fill) + fill_voxels(m, voxel, fill);
}

double cs_levelset_estimate_bytes(const cs_mesh_report *m, double voxel, double band, bool fill)
{
    return band_voxels(m, voxel, band, fill) * BAND_PEAK_BYTES +
           fill_voxels(m, voxel, fill) * FILL_PEAK_BYTES;
}

static double largest_extent(const cs_mesh_report *m)
{
    double e = 0;
    for (int k = 0; k < 3; k++)
        e = fmax(e, m->max[k] - m->min[k]);
    return e;
}

bool cs_levelset_voxel_ok(const cs_mesh_report *m, double voxel, double band, bool fill,
                          char *why, size_t len)
{
    double ext = largest_extent(m);
    if (!(voxel > 0) || !isfinite(voxel)) {
        snprintf(why, len, "must be a number > 0");
        return false;
    }
    if (voxel > ext / 4) {
        snprintf(why, len,
                 "must be at most a quarter of the mesh's largest extent, %.4g m, or the grid "
                 "could not tell its shape",
                 ext);
        return false;
    }
    double need = cs_levelset_estimate_bytes(m, voxel, band, fill);
    char fits[160];
    /* int32 voxel coordinates bound the grid whatever the memory */
    if (ext / voxel > 1e8 || !cs_memory_fits(need, fits, sizeof fits)) {
        snprintf(why, len, "%s (%.3g voxels at this size); use a larger voxel size",
                 ext / voxel > 1e8 ? "would need about 1e8 voxels along an axis, more "
                                     "than int32 coordinates hold"
                                   : fits,
                 cs_levelset_estimate_voxels(m, voxel, band, fill));
        return false;
    }
    return true;
}

bool cs_levelset_auto_fill(const cs_mesh_report *m, double voxel)
{
    return m->volume / (voxel * voxel * voxel) <= 2e6;
}

static double two_digits(double v)
{
    if (!(v > 0))
        return v;
    double e = pow(10.0, floor(log10(v)) - 1);
    return round(v / e) * e;
}

double cs_levelset_default_voxel(const cs_mesh_report *m, double cloth_edge, double band,
                                 bool fill)
{
    double ext = largest_extent(m);
    double v = cloth_edge > 0 ? 0.5 * cloth_edge : ext / 100;
    v = fmin(v, ext / 32);
    v = fmax(v, ext / 512);
    double budget = 1024.0 * 1024 * 1024, have = cs_memory_available();
    if (have > 0 && have / 4 < budget)
        budget = have / 4;
    for (int i = 0; i < 200 && cs_levelset_estimate_bytes(m, v, band, fill) > budget; i++)
        v *= 1.25;
    v = two_digits(v);
    return v > ext / 4 ? two_digits(ext / 4) : v;
}

/* ------------------------------------------------------------ cache */

static char *dup_str(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

static char *join(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    char *p = malloc(la + lb + 2);
    if (p)
        snprintf(p, la + lb + 2, "%s%s%s", a, la && a[la - 1] != '/' ? "/" : "", b);
    return p;
}

static bool is_off(const char *s) { return !strcmp(s, "none") || !strcmp(s, "off"); }

char *cs_levelset_cache_dir(const char *setting, const char *base_dir)
{
    const char *base = base_dir && *base_dir ? base_dir : ".";
    if (setting && *setting) {
        if (is_off(setting))
            return NULL;
        return setting[0] == '/' ? dup_str(setting) : join(base, setting);
    }
    const char *env = getenv("CLOTHSIM_CACHE");
    if (env && *env)
        return is_off(env) ? NULL : dup_str(env);
    env = getenv("XDG_CACHE_HOME");
    if (env && env[0] == '/')
        return join(env, "clothsim");
    env = getenv("HOME");
    if (env && env[0] == '/')
        return join(env, ".cache/clothsim");
    return join(base, ".clothsim-cache");
}

/* Files of an older key (SHA-256 named) simply never match a name. */
static void compute_key(const cs_trimesh *mesh, const cs_levelset_request *req,
                        char key[CS_LEVELSET_KEY_LEN])
{
    key[0] = '\0';
    XXH3_state_t *h = XXH3_createState();
    if (!h || XXH3_128bits_reset(h) != XXH_OK) {
        XXH3_freeState(h);
        return; /* no key: the cache is not used (an empty name never matches) */
    }
    char head[256];
    int n = snprintf(head, sizeof head, "clothsim level set 2\nopenvdb %s\nvoxel %.17g\nband %.17g\n"
                                        "fill %d\nvertices %d\ntriangles %d\n",
                     cs_levelset_library_version(), req->voxel_size, req->band,
                     req->fill_interior ? 1 : 0, mesh->nv, mesh->nt);
    XXH3_128bits_update(h, head, (size_t)n);
    /* what OpenVDB receives: 32-bit floats, little-endian as on every
     * machine this runs on */
    float buf[3 * 256];
    for (int i = 0; i < mesh->nv; i += 256) {
        int m = mesh->nv - i < 256 ? mesh->nv - i : 256;
        for (int k = 0; k < 3 * m; k++)
            buf[k] = (float)mesh->x[3 * i + k];
        XXH3_128bits_update(h, buf, 3 * (size_t)m * sizeof *buf);
    }
    for (int t = 0; t < 3 * mesh->nt; t++) {
        int32_t v = (int32_t)mesh->tri[t];
        XXH3_128bits_update(h, &v, sizeof v);
    }
    XXH128_canonical_t c;
    XXH128_canonicalFromHash(&c, XXH3_128bits_digest(h));
    XXH3_freeState(h);
    for (size_t i = 0; i < sizeof c.digest; i++)
        snprintf(key + 2 * i, 3, "%02x", c.digest[i]);
}

/* The label made safe for a file name. */
static void safe_label(const char *label, char *out, size_t len)
{
    size_t j = 0;
    for (const char *c = label && *label ? label : "mesh"; *c && j + 1 < len && j < 48; c++) {
        char ch = *c;
        bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
                  ch == '-' || ch == '_' || ch == '.';
        out[j++] = ok ? ch : '_';
    }
    out[j] = '\0';
}

int cs_levelset_build(const cs_trimesh *mesh, const cs_levelset_request *req,
                      cs_levelset_result *res, char *err, size_t errlen)
{
    memset(res, 0, sizeof *res);
    compute_key(mesh, req, res->key);
    double t0 = cs_now();
    if (req->cache_dir && res->key[0]) {
        char label[64];
        safe_label(req->label, label, sizeof label);
        snprintf(res->cache_path, sizeof res->cache_path, "%s/%s-%.16s.vdb", req->cache_dir,
                 label, res->key);
        if (access(res->cache_path, F_OK) == 0) {
            char why[400];
            res->grid = cs_levelset_read(res->cache_path, "clothsim_key", res->key, why,
                                         sizeof why);
            if (res->grid) {
                res->from_cache = true;
                res->seconds = cs_now() - t0;
                return CS_OK;
            }
            snprintf(res->cache_note, sizeof res->cache_note, "%s; converted again", why);
        }
    }
    res->grid = cs_levelset_create(mesh, req->voxel_size, req->band, req->fill_interior, err,
                                   errlen);
    if (!res->grid)
        return strstr(err ? err : "", "out of memory") ? CS_ERR_NOMEM : CS_ERR_BAD_INPUT;
    res->seconds = cs_now() - t0;
    if (req->cache_dir && res->key[0]) {
        char why[400], voxel[32];
        snprintf(voxel, sizeof voxel, "%.17g", req->voxel_size);
        const char *keys[] = {"clothsim_key", "clothsim_source", "clothsim_voxel_size"};
        const char *values[] = {res->key, req->label ? req->label : "", voxel};
        if (cs_make_dirs(req->cache_dir) != 0) {
            snprintf(res->cache_note, sizeof res->cache_note,
                     "cannot create the cache directory %s: %s; the grid is not kept",
                     req->cache_dir, strerror(errno));
            res->cache_path[0] = '\0';
        } else if (cs_levelset_write(res->grid, res->cache_path, "phi", 3, keys, values, why,
                                     sizeof why) != 0) {
            snprintf(res->cache_note, sizeof res->cache_note, "%s; the grid is not kept", why);
            res->cache_path[0] = '\0';
        }
    }
    return CS_OK;
}

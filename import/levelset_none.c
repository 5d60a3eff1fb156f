/* levelset_none.c: import/levelset.h in a build without OpenVDB
 * (-DCLOTHSIM_WITH_OPENVDB=OFF), in place of levelset.cpp: no grid can be
 * made or read, so a scene with a mesh body is refused with this sentence,
 * and nothing else changes. */
#include "import/levelset.h"

#include "common/error.h"
#include "common/util.h"

#include <string.h>

#define NO_OPENVDB \
    CS_MISSING_PART("OpenVDB", "level sets of mesh bodies need it", "CLOTHSIM_WITH_OPENVDB")

const char *cs_levelset_library_version(void) { return "none"; }

cs_levelset *cs_levelset_create(const cs_trimesh *mesh, double voxel_size, double band_voxels,
                                bool fill_interior, char *err, size_t errlen)
{
    (void)mesh, (void)voxel_size, (void)band_voxels, (void)fill_interior;
    cs_errorf(err, errlen, "%s", NO_OPENVDB);
    return NULL;
}

cs_levelset *cs_levelset_read(const char *path, const char *meta_key, const char *meta_value,
                              char *err, size_t errlen)
{
    (void)meta_key, (void)meta_value;
    cs_errorf(err, errlen, "cannot read %s: %s", path, NO_OPENVDB);
    return NULL;
}

/* There is never a grid to write, destroy, describe or sample. */
int cs_levelset_write(const cs_levelset *ls, const char *path, const char *grid_name, int nmeta,
                      const char *const *keys, const char *const *values, char *err,
                      size_t errlen)
{
    (void)ls, (void)grid_name, (void)nmeta, (void)keys, (void)values;
    cs_errorf(err, errlen, "cannot write %s: %s", path, NO_OPENVDB);
    return -1;
}

void cs_levelset_destroy(cs_levelset *ls) { (void)ls; }

void cs_levelset_get_info(const cs_levelset *ls, cs_levelset_info *info)
{
    (void)ls;
    memset(info, 0, sizeof *info);
}

double cs_levelset_phi(const void *ls, const double p[3], double grad[3])
{
    (void)ls, (void)p;
    grad[0] = grad[1] = grad[2] = 0;
    return 1;
}

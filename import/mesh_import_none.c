/* mesh_import_none.c: the mesh files of import/import.h in a build without
 * assimp (-DCLOTHSIM_WITH_ASSIMP=OFF), in place of mesh_import.c, mesh_io.c
 * and mesh_check.c: no mesh file is read or written, so a scene with a
 * mesh cloth or body is refused with this sentence. Cloths made as grids,
 * bodies of analytic shapes and the format names (mesh_format.c) are as in
 * any build. */
#include "import/import.h"

#include "common/error.h"
#include "common/util.h"

#include <string.h>

#define NO_ASSIMP \
    CS_MISSING_PART("assimp", "mesh files need it", "CLOTHSIM_WITH_ASSIMP")

/* The sentence for path; CS_ERR_FAILED. */
static int no_assimp(const char *path, char *err, size_t errlen)
{
    cs_errorf(err, errlen, "%s: %s", path ? path : "(no file)", NO_ASSIMP);
    return CS_ERR_FAILED;
}

int cs_mesh_write(const char *path, cs_mesh_format format, int nmeshes,
                  const cs_mesh_view *meshes, char *err, size_t errlen)
{
    (void)format, (void)nmeshes, (void)meshes;
    return no_assimp(path, err, errlen);
}

cs_trimesh *cs_mesh_read(const char *path, char *err, size_t errlen)
{
    no_assimp(path, err, errlen);
    return NULL;
}

int cs_mesh_read_named(const char *path, int n, const char *const *names, cs_trimesh **out,
                       char *err, size_t errlen)
{
    (void)names;
    for (int i = 0; i < n; i++)
        out[i] = NULL;
    return no_assimp(path, err, errlen);
}

int cs_mesh_import(const char *path, const cs_mesh_placement *place, cs_trimesh **out,
                   cs_mesh_report *report, char *err, size_t errlen)
{
    (void)place;
    *out = NULL;
    if (report)
        memset(report, 0, sizeof *report);
    return no_assimp(path, err, errlen);
}

int cs_mesh_catalog_read(const char *path, cs_mesh_catalog **out, char *err, size_t errlen)
{
    *out = NULL;
    return no_assimp(path, err, errlen);
}

/* No catalog is ever made here: nothing to free. */
void cs_mesh_catalog_destroy(cs_mesh_catalog *catalog) { (void)catalog; }

/* mesh_format.c: what import knows of mesh files without reading one, so
 * also in a build without assimp: the formats frames are written in, the
 * units a mesh file may be in, and the placement that leaves a mesh as it
 * is. Reading and writing is mesh_import.c's and mesh_io.c's (assimp). */
#include "import/import.h"

#include <stddef.h>
#include <string.h>
#include <strings.h>

/* ------------------------------------------------------------- formats */

static const char *const EXTENSIONS[] = {
    [CS_MESH_PLY] = "ply",
    [CS_MESH_OBJ] = "obj",
    [CS_MESH_GLB] = "glb",
};
#define NFORMATS ((int)(sizeof EXTENSIONS / sizeof EXTENSIONS[0]))

bool cs_mesh_format_from_name(const char *name, cs_mesh_format *format)
{
    if (!name)
        return false;
    cs_mesh_format f;
    if (strcasecmp(name, "ply") == 0)
        f = CS_MESH_PLY;
    else if (strcasecmp(name, "obj") == 0)
        f = CS_MESH_OBJ;
    else if (strcasecmp(name, "glb") == 0 || strcasecmp(name, "gltf") == 0)
        f = CS_MESH_GLB;
    else
        return false;
    if (format)
        *format = f;
    return true;
}

const char *cs_mesh_format_extension(cs_mesh_format format)
{
    if ((int)format < 0 || (int)format >= NFORMATS)
        return NULL;
    return EXTENSIONS[format];
}

/* ----------------------------------------------------------- placement */

cs_mesh_placement cs_default_mesh_placement(void)
{
    cs_mesh_placement p;
    memset(&p, 0, sizeof p);
    p.scale[0] = p.scale[1] = p.scale[2] = 1;
    p.rotation[0] = 1;
    return p;
}

bool cs_mesh_units_from_name(const char *name, double *metres)
{
    static const struct {
        const char *name;
        double metres;
    } units[] = {{"m", 1}, {"cm", 0.01}, {"mm", 0.001}, {"km", 1000},
                 {"in", 0.0254}, {"ft", 0.3048}};
    for (size_t i = 0; name && i < sizeof units / sizeof *units; i++)
        if (strcmp(name, units[i].name) == 0) {
            if (metres)
                *metres = units[i].metres;
            return true;
        }
    return false;
}

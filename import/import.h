/* import.h: the public face of clothsim's input and mesh-file side.
 *
 * Scene files (YAML, validated against a schema by libcyaml) become a
 * cs_scene holding a cs_sim_def ready for cs_sim_create; meshes are read and
 * written through assimp. Nothing here knows the simulation's internals: it
 * fills the public definition structs of sim/sim.h.
 */
#ifndef CS_IMPORT_H
#define CS_IMPORT_H

#include "sim/sim.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes of this module; a bad input file is CS_IMPORT_BAD_INPUT,
 * which the command turns into exit status 2. */
enum {
    CS_IMPORT_OK = 0,
    CS_IMPORT_BAD_INPUT = -10,   /* unreadable, malformed or invalid input */
    CS_IMPORT_NOMEM = -11,
};

/* ------------------------------------------------------------- scenes */

typedef struct cs_camera_def {
    bool given;                /* false: the renderer frames automatically */
    double position[3];
    double target[3];
    double up[3];
    double fov_degrees;        /* vertical field of view */
} cs_camera_def;

typedef struct cs_scene {
    char *name;                /* from the file, else the file's stem */
    char *path;                /* the file it came from ("<string>" if none) */
    int frames;                /* frames to simulate after the initial one */
    char *output_format;       /* "ply", "obj" or "glb" */
    cs_camera_def camera;
    double *cloth_colors;      /* 3 per cloth, linear RGB in [0,1] */
    double *body_colors;       /* 3 per body */
    cs_sim_def def;            /* every array it points to is owned here */
} cs_scene;

/* Loads and validates a scene file, then applies command-line overrides,
 * each "dotted.path=value" with value written in YAML (e.g.
 * "time.frames=10", "gravity=[0,-9.8,0]", "cloths.0.material.node_mass=2e-6").
 * On failure returns CS_IMPORT_BAD_INPUT and writes one line into err of the
 * form "FILE:LINE: KEY: what was expected" (or "--set KEY=VALUE: ..." when
 * an override is at fault). */
int cs_scene_load(const char *path, int noverrides, const char *const *overrides,
                  cs_scene **out, char *err, size_t errlen);

/* The same from text in memory; origin names it in messages. */
int cs_scene_load_string(const char *text, const char *origin,
                         int noverrides, const char *const *overrides,
                         cs_scene **out, char *err, size_t errlen);

void cs_scene_destroy(cs_scene *scene);

/* ------------------------------------------------------------- meshes */

typedef enum cs_mesh_format {
    CS_MESH_PLY = 0,   /* binary little-endian PLY */
    CS_MESH_OBJ,
    CS_MESH_GLB,       /* glTF 2.0 binary */
} cs_mesh_format;

/* "ply", "obj", "glb" (also "gltf" for glb) -> format; returns false if unknown. */
bool cs_mesh_format_from_name(const char *name, cs_mesh_format *format);
const char *cs_mesh_format_extension(cs_mesh_format format);

/* A borrowed view of one named triangle mesh to write. */
typedef struct cs_mesh_view {
    const char *name;
    int nv;
    const double *x;     /* 3 per vertex */
    int nt;
    const int *tri;      /* 3 per triangle */
} cs_mesh_view;

/* Writes the meshes as one file through assimp's exporter. The file appears
 * atomically (written beside it, then renamed), so a frame on disk is always
 * complete. Returns CS_IMPORT_OK or CS_IMPORT_BAD_INPUT with err filled. */
int cs_mesh_write(const char *path, cs_mesh_format format, int nmeshes,
                  const cs_mesh_view *meshes, char *err, size_t errlen);

/* Reads every mesh of a file through assimp (triangulated, identical
 * vertices joined) merged into one cs_trimesh. NULL with err on failure. */
cs_trimesh *cs_mesh_read(const char *path, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif
#endif

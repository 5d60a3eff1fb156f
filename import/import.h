/* import.h: the public face of clothsim's input and mesh-file side.
 *
 * Scene files (YAML, validated against a schema by libcyaml) become a
 * cs_scene holding a cs_sim_def ready for cs_sim_create; meshes are read and
 * written through assimp. Nothing here knows the simulation's internals: it
 * fills the public definition structs of sim/sim.h.
 */
#ifndef CS_IMPORT_H
#define CS_IMPORT_H

#include <stdbool.h>
#include <stdio.h>

#include "common/error.h"
#include "import/levelset.h"
#include "sim/sim.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Statuses (common/error.h): a bad input file is CS_ERR_BAD_INPUT, which
 * the command turns into exit status 2; CS_ERR_NOMEM. */

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
 * complete. A mesh with vertices and no triangles (nt 0) is written as
 * points: PLY vertices only, OBJ "p" lines, glTF POINTS. Returns
 * CS_OK or CS_ERR_BAD_INPUT with err filled. */
int cs_mesh_write(const char *path, cs_mesh_format format, int nmeshes,
                  const cs_mesh_view *meshes, char *err, size_t errlen);

/* Reads every mesh of a file through assimp (triangulated; vertices of
 * OBJ, STL and other formats that list them per corner joined; PLY and
 * glTF numbered as written) merged into one cs_trimesh, as
 * cs_mesh_import does it (in a child process). Meshes without triangles
 * give their vertices: a frame of a cloth without triangles is a point
 * cloud (nt 0). NULL with err on failure. */
cs_trimesh *cs_mesh_read(const char *path, char *err, size_t errlen);

/* The same for the named meshes of a file (cs_mesh_write's views, one
 * child process for all): out[i] gets the nodes and meshes named names[i],
 * merged. Returns CS_OK, or a cs_status with err (a name
 * the file does not have is CS_ERR_BAD_INPUT) and every out[i] NULL. */
int cs_mesh_read_named(const char *path, int n, const char *const *names, cs_trimesh **out,
                       char *err, size_t errlen);

/* --------------------------------------------------------- mesh import */

/* Which part of a mesh file to take, and where to put it. A vertex p of
 * the file (node transforms applied) lands at
 *     translate + R(rotation) (scale * (unit_scale * p)). */
typedef struct cs_mesh_placement {
    const char *node;          /* NULL: every mesh of the file, merged; else
                                  the nodes (with their subtrees) and meshes
                                  of that name */
    double unit_scale;         /* metres per file unit; 0: from the file
                                  (FBX UnitScaleFactor; others are metres) */
    double scale[3];
    double rotation[4];        /* unit quaternion w, x, y, z */
    double translate[3];
} cs_mesh_placement;

cs_mesh_placement cs_default_mesh_placement(void);

/* "m", "cm", "mm", "km", "in", "ft" -> metres per unit; false if unknown. */
bool cs_mesh_units_from_name(const char *name, double *metres);

/* What import saw and did. */
typedef struct cs_mesh_report {
    char format[64];             /* assimp's importer, e.g. "glTF2 Importer" */
    char units[128];             /* how file units became metres */
    double unit_scale;           /* metres per file unit applied */
    int file_meshes, file_nodes; /* in the whole file */
    int instances;               /* mesh instances merged */
    long triangles_read;         /* after triangulation */
    long skipped_primitives;     /* points and lines, ignored */
    int vertices, triangles;     /* of the result */
    int welded_vertices;         /* joined with another at the same position */
    int unreferenced_vertices;   /* dropped */
    int degenerate_triangles;    /* zero area, dropped */
    int duplicate_triangles;     /* same three vertices as another, dropped */
    int boundary_edges;          /* used by one triangle */
    int boundary_loops;
    int nonmanifold_edges;       /* used by more than two triangles */
    int inconsistent_edges;      /* two neighbours that disagree on orientation */
    int parts;                   /* connected components */
    bool closed;                 /* no boundary and no non-manifold edge */
    double min[3], max[3];       /* bounds of the result, m */
    double area;                 /* m^2 */
    double volume;               /* m^3 enclosed, from the divergence theorem */
    char size_warning[320];      /* "" or why the size looks like wrong units
                                    (a format without units, e.g. an STL in
                                    millimetres read as metres) */
} cs_mesh_report;

/* Reads a mesh file through assimp (OBJ, PLY, STL, glTF 2.0, FBX, Collada
 * and whatever else assimp reads), triangulated, node transforms applied,
 * the selected meshes merged and placed; then joins vertices at identical
 * positions and drops zero-area and duplicate triangles and unreferenced
 * vertices, counting each in the report (which may be NULL). A missing,
 * unreadable or corrupt file, a node that is not there, a non-finite
 * coordinate, a result without triangles or one whose triangles use less
 * than half of the vertices (most of the file not understood) is
 * CS_ERR_BAD_INPUT with a sentence in err. The file is read in a child
 * process with limits on time and memory, so that no file can crash or
 * hang the caller (limits: CLOTHSIM_IMPORT_SECONDS of CPU, default 30 + 1
 * per MB of file; CLOTHSIM_IMPORT_MEMORY MB, default 1024 + 64 per MB). */
int cs_mesh_import(const char *path, const cs_mesh_placement *place, cs_trimesh **out,
                   cs_mesh_report *report, char *err, size_t errlen);

/* Topology counts of a mesh (the last fields of the report, from
 * boundary_edges on). */
void cs_mesh_analyse(const cs_trimesh *mesh, cs_mesh_report *report);

/* Closes every boundary loop with a fan of triangles to the loop's centroid,
 * oriented like its neighbours: what a level set needs for a sign. Returns
 * the loops closed (0: nothing to do), or -1 when memory runs out. */
int cs_mesh_close_holes(cs_trimesh **mesh);

/* The nodes and meshes of a file, for `clothsim mesh-info`. */
typedef struct cs_mesh_catalog_node {
    char *name;
    int depth;                   /* 0 for the root */
    int nmeshes;                 /* meshes this node instances */
    int *meshes;
} cs_mesh_catalog_node;

typedef struct cs_mesh_catalog_mesh {
    char *name;
    int vertices;
    int triangles;               /* after triangulation */
    int other_primitives;        /* points and lines */
} cs_mesh_catalog_mesh;

typedef struct cs_mesh_catalog {
    char format[64];
    int nnodes;
    cs_mesh_catalog_node *nodes; /* depth first, parents before children */
    int nmeshes;
    cs_mesh_catalog_mesh *meshes;
} cs_mesh_catalog;

int cs_mesh_catalog_read(const char *path, cs_mesh_catalog **out, char *err, size_t errlen);
void cs_mesh_catalog_destroy(cs_mesh_catalog *catalog);

/* ---------------------------------------------------- level-set bodies */

/* A grid's inside: distances all the way in, or a band as wide as the
 * outside one (deeper points read -band, with no gradient). */
typedef enum cs_interior_mode {
    CS_INTERIOR_AUTO = 0,      /* fill when cs_levelset_auto_fill says so */
    CS_INTERIOR_FILL,
    CS_INTERIOR_BAND,
} cs_interior_mode;

/* What a grid is made from besides the mesh. */
typedef struct cs_levelset_request {
    double voxel_size;         /* m, > 0 */
    double band;               /* narrow band, voxels, >= 1 */
    bool fill_interior;        /* every voxel inside holds its distance;
                                  else the interior band is band wide */
    const char *cache_dir;     /* NULL: no cache */
    const char *label;         /* start of the cache file's name, e.g. the
                                  mesh file's stem */
} cs_levelset_request;

#define CS_LEVELSET_KEY_LEN 33    /* 32 hex digits and the NUL */

typedef struct cs_levelset_result {
    cs_levelset *grid;
    bool from_cache;           /* read from cache_path */
    char cache_path[1024];     /* the .vdb read or written; "" if none */
    char cache_note[512];      /* why the cache could not be used, or "" */
    char key[CS_LEVELSET_KEY_LEN]; /* XXH3-128 of everything the grid depends on,
                                     in hex; "" if it could not be computed */
    double seconds;            /* converting or reading */
} cs_levelset_result;

/* The grid of a mesh (in its own frame): read from the cache when a file
 * there was made from the same mesh (after placement and repairs), voxel
 * size, band and OpenVDB version, keyed by the XXH3-128 hash of them; otherwise
 * converted and written there. A cache that cannot be read or written is
 * a note, not an error. */
int cs_levelset_build(const cs_trimesh *mesh, const cs_levelset_request *req,
                      cs_levelset_result *res, char *err, size_t errlen);

/* The cache directory: setting (a path relative to base_dir, or "none"),
 * else $CLOTHSIM_CACHE (a path, or "none"), else $XDG_CACHE_HOME/clothsim,
 * else $HOME/.cache/clothsim, else base_dir/.clothsim-cache. NULL when
 * caching is off (or out of memory). Free with free(). */
char *cs_levelset_cache_dir(const char *setting, const char *base_dir);

/* Voxels and bytes (at the peak of conversion) a grid of this voxel size
 * would take, estimated from the mesh's area and volume. */
double cs_levelset_estimate_voxels(const cs_mesh_report *mesh, double voxel, double band,
                                   bool fill_interior);
double cs_levelset_estimate_bytes(const cs_mesh_report *mesh, double voxel, double band,
                                  bool fill_interior);
/* memory.c: memory available now (MemAvailable), bytes; 0 if unknown. */
double cs_memory_available(void);
/* "310 GB", "2.5 MB": three significant digits. */
void cs_format_bytes(double bytes, char *buf, size_t len);
/* True when need bytes fit in three quarters of what is available; else
 * false with "would need about X of memory, but Y is available" in why. */
bool cs_memory_fits(double need, char *why, size_t len);

/* True when the voxel size suits the mesh: at most a quarter of its largest
 * extent, and the estimated memory within what is available. Else false,
 * with a phrase in why ("would need about 310 GB (...) but ..."). */
bool cs_levelset_voxel_ok(const cs_mesh_report *mesh, double voxel, double band,
                          bool fill_interior, char *why, size_t len);

/* Whether to fill the interior when the scene leaves it to us: when it
 * holds at most 2 million voxels (some 10 MB and a few seconds); beyond,
 * the interior gets a band as wide as the exterior one. */
bool cs_levelset_auto_fill(const cs_mesh_report *mesh, double voxel);

/* The default voxel size: half the cloth's median edge (cloth_edge; 0 for
 * none: 1/100 of the mesh's largest extent), kept within 1/32 and 1/512 of
 * that extent, coarsened until the estimate fits 1 GiB and a quarter of the
 * available memory; two significant digits, so a cache survives small
 * changes of the cloth. */
double cs_levelset_default_voxel(const cs_mesh_report *mesh, double cloth_edge, double band,
                                 bool fill_interior);

/* The mesh a mesh body's grid is made of (shared by scenes and `clothsim
 * levelset`): mesh itself when it is closed or close_holes is false, else a
 * copy with each boundary loop closed by a fan (*holes_closed of them),
 * which the caller destroys. *closed gets the report of what is returned.
 * NULL when memory runs out. */
cs_trimesh *cs_mesh_body_sign_mesh(cs_trimesh *mesh, const cs_mesh_report *rep, bool close_holes,
                                   int *holes_closed, cs_mesh_report *closed);

/* The grid of a mesh body: *voxel as given (> 0), else the default for
 * cloth_edge (see cs_levelset_default_voxel); *fill as interior says (auto:
 * cs_levelset_auto_fill); *band, given as the scene's band beyond the
 * collision surface (offset m out from the mesh), becomes the band the grid
 * needs, in voxels. False, with a phrase in why, when the voxel size does
 * not suit the mesh (cs_levelset_voxel_ok). */
bool cs_mesh_body_grid(const cs_mesh_report *mesh, double *voxel, double cloth_edge, double offset,
                       double *band, cs_interior_mode interior, bool *fill, char *why,
                       size_t len);

/* ------------------------------------------------------------- scenes */

typedef struct cs_camera_def {
    bool given;                /* false: the renderer frames automatically */
    double position[3];
    double target[3];
    double up[3];
    double fov_degrees;        /* vertical field of view */
    cs_motion motion;          /* frame at target, no rotation at t = 0;
                                  carries the eye, target and up over time */
} cs_camera_def;

/* A body made from a mesh: what was read, and the grid made of it. */
typedef struct cs_scene_mesh_body {
    char *file;                /* the mesh file as opened */
    cs_trimesh *mesh;          /* in the body's local frame, as imported (for
                                  drawing; the grid may have holes closed) */
    cs_mesh_report report;
    cs_trimesh *sign_mesh;     /* what the grid is made of: mesh, with its
                                  holes closed when close_holes */
    double voxel_size;         /* m, given or chosen */
    double band;               /* narrow band beyond the collision offset,
                                  voxels (the scene's `band`) */
    double grid_band;          /* the grid's band: band plus the offset in
                                  voxels (cs_mesh_body_grid) */
    cs_interior_mode interior; /* as the scene asked */
    bool fill_interior;        /* as decided: distances all the way in */
    bool close_holes;
    int holes_closed;          /* boundary loops closed for the sign */
    cs_levelset *levelset;     /* the body's phi_data */
    char *cache_path;          /* .vdb read or written; NULL if none */
    bool from_cache;
    double seconds;            /* converting or reading the grid */
} cs_scene_mesh_body;

/* A file a scene reads, to be copied into a run folder with its scene. */
typedef struct cs_scene_asset {
    char *source;              /* the file as read */
    char *name;                /* where the resolved scene expects it, relative
                                  to its folder: assets/<hash>/<file name> for
                                  a mesh (the hash of its bytes), assets/<file
                                  name> for a cached grid (named by its key) */
} cs_scene_asset;

typedef struct cs_scene {
    char *name;                /* from the file, else the file's stem */
    char *path;                /* the file it came from ("<string>" if none) */
    int frames;                /* frames to simulate after the initial one */
    char *output_format;       /* "ply", "obj" or "glb" */
    bool output_usd;           /* output.usd: `run` writes DIR/cloth.usda */
    bool output_pc2;           /* output.pc2: `run` writes DIR/pc2/ */
    cs_camera_def camera;
    double *cloth_colors;      /* 3 per cloth, linear RGB in [0,1] */
    double *body_colors;       /* 3 per body */
    cs_sim_def def;            /* every array it points to is owned here */
    cs_scene_mesh_body *mesh_bodies; /* one per body (mesh NULL for analytic
                                        bodies); NULL without bodies */
    char *levelset_cache;      /* folder of cached grids; NULL: no cache */
    int nnotes;                /* what import did and warnings, one line each,
                                  for the user ("warning: " first if one) */
    char **notes;
    bool allow_intersecting_start; /* check.allow_intersecting_start: `run`
                                      starts from intersecting cloth */
    /* The resolved scene: YAML holding every key with its value (defaults
     * written out, overrides applied, names and voxel sizes as chosen),
     * mesh files and the level-set cache in assets/ beside it. Loaded from
     * a folder holding it and its assets, it gives this scene again. */
    char *resolved;
    size_t resolved_len;
    char *resolved_setup;      /* the same without time.frames: what a resumed
                                  run must share with the run it continues */
    size_t resolved_setup_len;
    int nassets;
    cs_scene_asset *assets;
} cs_scene;

/* Loads and validates a scene file, then applies command-line overrides,
 * each "dotted.path=value" with value written in YAML (e.g.
 * "time.frames=10", "gravity=[0,-9.8,0]", "cloths.0.material.node_mass=2e-6").
 * On failure returns CS_ERR_BAD_INPUT and writes one line into err of the
 * form "FILE:LINE: KEY: what was expected" (or "--set KEY=VALUE: ..." when
 * an override is at fault). */
int cs_scene_load(const char *path, int noverrides, const char *const *overrides,
                  cs_scene **out, char *err, size_t errlen);

/* The same from text in memory; origin names it in messages. */
int cs_scene_load_string(const char *text, const char *origin,
                         int noverrides, const char *const *overrides,
                         cs_scene **out, char *err, size_t errlen);

void cs_scene_destroy(cs_scene *scene);

/* The scene file reference, made from the table of keys (scene_keys.def):
 * as text for `clothsim help scene`, or (markdown) as the tables
 * docs/scene-reference.md
 * holds between <!-- scene-reference:begin SECTION --> and
 * <!-- scene-reference:end SECTION --> lines. */
void cs_scene_reference(FILE *out, bool markdown);

#ifdef __cplusplus
}
#endif
#endif

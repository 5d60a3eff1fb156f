/* scene_schema.h: private to the scene loader.
 *
 * The raw structs libcyaml fills from a scene file, the schema that drives
 * it, and small queries on that schema (the schema of a key path, a phrase
 * for what a value should look like). Optional scalars are pointers so that
 * an explicit 0 differs from an absent key (NULL).
 */
#ifndef CS_SCENE_SCHEMA_H
#define CS_SCENE_SCHEMA_H

#include <stdbool.h>
#include <stddef.h>

#include <cyaml/cyaml.h>

typedef struct cs_raw_time {
    double *fps;
    int *frames;
    char *dt;                  /* a number or "auto": checked after loading */
    double *dt_safety;
    int *collision_steps;
    double *cg_tolerance;
    int *cg_max_iterations;
} cs_raw_time;

typedef struct cs_raw_effects {
    bool *bodies;
    bool *wind;
    bool *self_collision;
    int *friction;             /* cs_friction_method */
} cs_raw_effects;

typedef struct cs_raw_self {
    double *thickness;
    double *stiffness;
    double *friction;
    double *edge_flip_epsilon;
    int *zone_iterations;
    int *scheme;               /* cs_collision_scheme */
    bool *verify;
} cs_raw_self;

typedef struct cs_raw_wind {
    double *velocity;          /* 3 */
    double *drag;
} cs_raw_wind;

typedef struct cs_raw_output {
    int *format;               /* index into cs_scene_format_names */
} cs_raw_output;

typedef struct cs_raw_camera {
    double *position;          /* 3, required */
    double *target;            /* 3, required */
    double *up;                /* 3 */
    double *fov;
} cs_raw_camera;

typedef struct cs_raw_grid {
    double *size;              /* 2 */
    int *resolution;           /* 2 */
    double *center;            /* 3 */
    double *rotation;          /* 3, degrees */
} cs_raw_grid;

typedef struct cs_raw_mesh {
    char *file;                /* a mesh file, relative to the scene's folder */
    char *node;                /* a node or mesh of that file */
    int *units;                /* index into cs_scene_unit_names */
    /* scale: a number or 3 numbers, read from the document (cyaml has no
     * either-or type) */
    double (*vertices)[3];
    unsigned vertices_count;
    int (*triangles)[3];
    unsigned triangles_count;
    double *rotation;          /* 3, degrees */
    double *translate;         /* 3 */
} cs_raw_mesh;

typedef struct cs_raw_material {
    double *edge_stiffness;
    double *edge_overdamping;
    double *bend_stiffness;
    double *bend_overdamping;
    double *node_mass;
    double *density;
} cs_raw_material;

typedef struct cs_raw_box {
    double *min;               /* 3, required */
    double *max;               /* 3, required */
} cs_raw_box;

typedef struct cs_raw_selection {
    int *vertices;
    unsigned vertices_count;
    cs_raw_box *box;
    int (*grid_points)[2];
    unsigned grid_points_count;
} cs_raw_selection;

typedef struct cs_raw_key {
    double time;               /* required */
    double *translate;         /* 3 */
    double *rotate;            /* 3, degrees */
} cs_raw_key;

typedef struct cs_raw_motion {
    double *velocity;          /* 3 */
    double *angular_velocity;  /* 3, rad/s */
    cs_raw_key *keys;
    unsigned keys_count;
} cs_raw_motion;

typedef struct cs_raw_script {
    cs_raw_selection *select;  /* required */
    double *pivot;             /* 3 */
    cs_raw_motion *motion;
} cs_raw_script;

typedef struct cs_raw_cloth {
    char *name;
    double *color;             /* 3 */
    cs_raw_grid *grid;
    cs_raw_mesh *mesh;
    cs_raw_material *material;
    double *velocity;          /* 3 */
    cs_raw_selection *pins;
    unsigned pins_count;
    cs_raw_script *scripts;
    unsigned scripts_count;
} cs_raw_cloth;

typedef struct cs_raw_body {
    char *name;
    int shape;                 /* cs_body_shape, required */
    double *position;          /* 3 */
    double *rotation;          /* 3, degrees */
    double *normal;            /* 3, planes only */
    double *radius;
    double *size;              /* 3 */
    double *height;
    double *friction;
    double *collision_offset;
    double *color;             /* 3 */
    cs_raw_motion *motion;
    cs_raw_mesh *mesh;         /* mesh bodies */
    double *voxel_size;
    double *band;
    bool *close_holes;
    int *interior;             /* cs_interior_mode */
} cs_raw_body;

typedef struct cs_raw_levelset {
    char *cache;               /* a folder, or "none" */
} cs_raw_levelset;

typedef struct cs_raw_scene {
    char *name;
    char *description;
    cs_raw_time *time;
    double *gravity;           /* 3 */
    cs_raw_effects *effects;
    cs_raw_self *self_collision;
    cs_raw_wind *wind;
    cs_raw_output *output;
    cs_raw_camera *camera;
    cs_raw_cloth *cloths;
    unsigned cloths_count;
    cs_raw_body *bodies;
    unsigned bodies_count;
    cs_raw_levelset *levelset;
} cs_raw_scene;

/* The top-level schema (a pointer to cs_raw_scene). */
extern const cyaml_schema_value_t cs_scene_schema;

/* Output format names, indexed by cs_raw_output.format. */
extern const char *const cs_scene_format_names[];

/* Mesh units, indexed by cs_raw_mesh.units; 0 is "auto". */
extern const char *const cs_scene_unit_names[];
#define CS_SCENE_UNIT_COUNT 7

/* A key path: mapping keys and sequence indices, outermost first. Keys
 * longer than the buffer are cut (they then match nothing). */
#define CS_SPATH_MAX 48
#define CS_SPATH_KEY 96
typedef struct cs_spath {
    int n;
    struct {
        char key[CS_SPATH_KEY];  /* "" for an index component */
        long index;              /* >= 0 for an index component */
    } c[CS_SPATH_MAX];
} cs_spath;

void cs_spath_push_key(cs_spath *p, const char *key, size_t len);
void cs_spath_push_index(cs_spath *p, long index);
/* Parses "a.b[2].c" or "a.b.2.c" (a purely numeric component between dots
 * stays a key; the locator treats it as an index inside a sequence).
 * Returns false on an empty component or a malformed bracket. */
bool cs_spath_parse(cs_spath *p, const char *text);
/* Writes "a.b[2].c" (numeric dotted components are written as [N]). */
void cs_spath_format(const cs_spath *p, char *buf, size_t len);

/* The schema of the value at a path, or NULL where the path leaves it. */
const cyaml_schema_value_t *cs_scene_schema_at(const cs_spath *p);

/* A phrase for what a value with this schema looks like: "a number",
 * "one of ply, obj, glb", "a list of 3 numbers", ... */
void cs_scene_schema_describe(const cyaml_schema_value_t *v, char *buf, size_t len);

/* True for a non-empty string of decimal digits (a sequence index). */
bool cs_all_digits(const char *s);

#endif

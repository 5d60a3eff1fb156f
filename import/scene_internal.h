/* scene_internal.h: private to the scene loader (import/scene_*.c).
 *
 * A load (scene_load.c) runs in stages, each with one-line error messages:
 *   1. libyaml parses the text into a document (scene_doc.c);
 *   2. libcyaml loads it against the schema (scene_schema.c, made from
 *      scene_keys.def); scene_errors.c turns its log into "KEY.PATH: what
 *      was expected (got X)" placed at the key's line, and checks number
 *      and boolean text strictly (cyaml 1.3 reads "3x" as 3);
 *   3. --set overrides: each value is parsed into the document, from where
 *      it goes into the raw structs through its key's row (scene_set.c);
 *   4. the raw structs become a cs_scene (scene_convert.c, scene_cloth.c,
 *      scene_mesh.c, each calling only the ones after it), each value
 *      checked once against its key's range (scene_values.c);
 *   5. mesh bodies get their level sets (scene_mesh.c);
 *   6. the resolved scene is written back as YAML (scene_emit.c).
 * The document stays alive to the end so that every message can be placed.
 */
#ifndef CS_SCENE_INTERNAL_H
#define CS_SCENE_INTERNAL_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>

#include "import/import.h"
#include "import/scene_doc.h"
#include "import/scene_schema.h"

#define MSG_LEN 512
#define PATH_LEN 256

typedef struct loader {
    const char *file;            /* the name messages use */
    cs_sdoc doc;
    int noverrides;
    const char *const *overrides;
    /* The pending error, placed (file line or override) by cs_sl_report. */
    cs_spath err_path;
    bool err_second;             /* the path's last key is a duplicate */
    char err_msg[MSG_LEN];
    /* libcyaml's log of the current load. */
    char log[16384];
    size_t log_len;
    /* for refusing a grid that cannot fit before tessellating it */
    bool self_collision;
    double particles;            /* of the cloths converted so far */
} loader;

/* ------------------------------------------------ scene_errors.c */

/* One line into err, whatever the values quoted in it contain. */
void cs_sl_set_err(char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Records the pending error at a key path; with_got appends "(got X)" with
 * the value found there. Return CS_ERR_BAD_INPUT. */
int cs_sl_fail_at(loader *L, const cs_spath *p, bool with_got, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
int cs_sl_fail(loader *L, const char *path, bool with_got, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* Writes the pending error: "--set OVERRIDE: PATH: msg" where an override
 * made the nodes on the path (or blame says so), else "FILE:LINE: PATH: msg". */
int cs_sl_report(loader *L, bool blame, char *err, size_t errlen);
/* Stages 2 on text whose document is L->doc. */
int cs_sl_load_raw(loader *L, const char *text, size_t len, cs_raw_scene **raw);
void cs_sl_free_raw(loader *L, cs_raw_scene *raw);
/* A value of the wrong kind at p: "expected X (got Y)". */
int cs_sl_fail_type(loader *L, const cs_spath *p);
/* Number, integer and boolean text of node n, whose schema is v, as
 * strictly as the file's own is checked. */
int cs_sl_check_scalar(loader *L, const yaml_node_t *n, const cyaml_schema_value_t *v,
                       const cs_spath *p);
/* Frees a value libcyaml's way (v a pointer schema; count: of a sequence). */
void cs_sl_free_value(loader *L, const cyaml_schema_value_t *v, void *data, unsigned count);

/* ------------------------------------------------ scene_set.c */

/* The override whose value cs_sdoc_set put at path p of the document,
 * into raw: the member of the innermost section on p, replaced whole. */
int cs_sl_apply_override(loader *L, cs_raw_scene *raw, const cs_spath *p);
/* Every required key of the mappings under raw (of section sec) is there;
 * p: raw's path, given back as it came. */
int cs_sl_check_required(loader *L, int sec, const void *raw, cs_spath *p);

/* ------------------------------------------------ scene_values.c */

/* Values of keys (scene_keys.def) under base ("" at the top level), checked
 * against the key's range; an absent one gets the key's default (for a
 * vector, def when not NULL), or keeps *out without one. index >= 0 names
 * one entry of the key (an entry of a list of integers). */
int cs_sl_num(loader *L, const cs_scene_key *k, const double *v, const char *base, double *out);
int cs_sl_int(loader *L, const cs_scene_key *k, const int *v, const char *base, int index,
              int *out);
int cs_sl_vec(loader *L, const cs_scene_key *k, const double *v, const char *base,
              const double *def, double *out);
/* Every key of the section that scene_keys.def converts TO a field of
 * target, in the table's order. */
int cs_sl_convert_keys(loader *L, int section, const void *raw, const char *base, void *target);
/* "must not be empty" for a given, empty name. */
int cs_sl_check_name(loader *L, const char *name, const char *path);
/* The name of entry index of list ("cloths"): the one given (not empty),
 * else stem and index ("cloth0"); unique among the entries before
 * (before(s, j) names them). *out is malloc'd, also on failure. */
int cs_sl_entry_name(loader *L, const char *given, const char *list, const char *stem, int index,
                     const char *(*before)(const cs_scene *, int), const cs_scene *s, char **out);

char *cs_sl_strdup(const char *s);
/* A line for the user (see cs_scene.notes); false when memory runs out. */
bool cs_sl_note(cs_scene *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* The folder of the scene file, to which its paths are relative. */
char *cs_sl_scene_dir(const char *file);
const char *cs_sl_base_name(const char *path);

/* ------------------------------------------------ scene_convert.c */

int cs_sl_convert_scene(loader *L, const cs_raw_scene *r, const char *default_name,
                        cs_scene **out);

/* ------------------------------------------------ scene_cloth.c */

/* A motion of a frame whose initial pose is (pos, rot). */
int cs_sl_convert_motion(loader *L, const cs_raw_motion *rm, const char *path,
                         const double pos[3], const double rot[4], cs_motion *m);
int cs_sl_convert_cloth(loader *L, const cs_raw_cloth *rc, int ci, cs_scene *s);

/* ------------------------------------------------ scene_mesh.c */

/* path relative to the scene file's folder, unless absolute (malloc'd). */
char *cs_sl_scene_relative(const char *file, const char *path);
/* mesh.scale at path: one number or three, from the document. */
int cs_sl_read_scale(loader *L, const char *path, double out[3]);
/* The mesh block at base.mesh: a file through assimp (*file: the path as
 * opened) or inline vertices. */
int cs_sl_convert_mesh(loader *L, const cs_raw_mesh *m, const char *base, cs_trimesh **mesh,
                       cs_mesh_report *rep, char **file);
/* One line on what import did with a mesh file, and warnings. */
bool cs_sl_note_mesh(cs_scene *s, const char *who, const char *file, const cs_mesh_report *r,
                     bool body);
/* The mesh and grid settings of mesh body bi; the grid comes later. */
int cs_sl_convert_mesh_body(loader *L, const cs_raw_body *rb, int bi, cs_scene *s);
/* Voxel sizes, their check against mesh and memory, holes closed. */
int cs_sl_finish_mesh_bodies(loader *L, cs_scene *s);
/* The grids themselves, once the whole scene converted. */
int cs_sl_build_levelsets(loader *L, cs_scene *s);

/* ------------------------------------------------ scene_emit.c */

/* The resolved scene of r (cs_scene.resolved, .resolved_setup) and the
 * files to copy with it (cs_scene.assets), once s is complete. */
int cs_sl_resolve(loader *L, const cs_raw_scene *r, cs_scene *s);

#endif

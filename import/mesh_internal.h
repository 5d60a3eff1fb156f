/* mesh_internal.h: private to import/'s mesh files (mesh_import.c,
 * mesh_guard.c, mesh_check.c, mesh_repair.c); not part of import.h.
 *
 * Reading a mesh file goes: cs_mesh_precheck (the file's own claims
 * checked against its size, before assimp trusts them) -> assimp without
 * post-processing -> cs_mesh_check_scene (face indices, corner counts) ->
 * assimp's post-processing -> our walk; all of it inside cs_guard_run's
 * child process, so that what assimp does to itself on a corrupt file stays
 * there. */
#ifndef CS_MESH_INTERNAL_H
#define CS_MESH_INTERNAL_H

#include "import/import.h"

#include <stdbool.h>
#include <stddef.h>

#include "common/util.h"

struct aiScene;

/* snprintf into err when err is not NULL (common/util.h). */
#define cs_mesh_set_err cs_errorf

/* ------------------------------------------------------- byte buffers */

/* A growable byte buffer: what the child sends back. */
typedef struct cs_bytes {
    unsigned char *data;
    size_t len, cap;
    bool nomem;              /* an append failed: the content is incomplete */
} cs_bytes;

void cs_bytes_put(cs_bytes *b, const void *p, size_t n);
void cs_bytes_put_str(cs_bytes *b, const char *s);
void cs_bytes_free(cs_bytes *b);

/* Reads a cs_bytes back; any read past the end sets bad and yields zeros. */
typedef struct cs_bytes_reader {
    const unsigned char *p;
    size_t left;
    bool bad;
} cs_bytes_reader;

void cs_bytes_get(cs_bytes_reader *r, void *out, size_t n);
/* A string written by cs_bytes_put_str, copied into out (truncated to len). */
void cs_bytes_get_str(cs_bytes_reader *r, char *out, size_t len);
/* The same, malloc'd; NULL when bad or out of memory. */
char *cs_bytes_get_strdup(cs_bytes_reader *r);
/* A pointer to the next n bytes (NULL, and bad set, if there are fewer). */
const void *cs_bytes_take(cs_bytes_reader *r, size_t n);

/* ------------------------------------------------------------- guard */

/* Work to do in the child: fills out and returns a cs_status with
 * a sentence in err on failure. */
typedef int (*cs_guarded_fn)(void *ctx, cs_bytes *out, char *err, size_t errlen);

/* Runs fn in a child process limited in CPU time, memory and wall-clock
 * time (sized from the size of the file at path), and returns its status
 * with what it wrote in *result, on failure too (free it with
 * cs_bytes_free). A child that crashes, runs out of time or memory, or
 * answers nonsense is CS_ERR_BAD_INPUT with err saying which, and an
 * empty result. CLOTHSIM_IMPORT_ISOLATION=0 runs fn in this process. */
int cs_guard_run(const char *path, cs_guarded_fn fn, void *ctx, cs_bytes *result, char *err,
                 size_t errlen);

/* --------------------------------------------------------- pre-checks */

typedef enum cs_mesh_kind {
    CS_KIND_OTHER = 0,
    CS_KIND_PLY,             /* "ply" magic */
    CS_KIND_GLTF,            /* glTF binary magic, or a .gltf file */
    CS_KIND_OBJ,             /* a .obj file */
} cs_mesh_kind;

/* The largest polygon read: assimp's triangulation takes quadratic time in
 * a face's corners (a face of hundreds of thousands of corners runs for
 * minutes); a face of this many is read in well under a second. */
#define CS_MESH_MAX_CORNERS 10000

/* The most digits of a number read from a text file: a double needs 17
 * ("-1.2345678901234567e-308"); a coordinate of a million digits is not a
 * mesh. */
#define CS_MESH_MAX_NUMBER_DIGITS 100

typedef struct cs_mesh_precheck_result {
    cs_mesh_kind kind;
    unsigned char *data;     /* non-NULL: import this copy from memory */
    size_t len;
    const char *hint;        /* its format, for aiImportFileFromMemory */
} cs_mesh_precheck_result;

/* What can be checked before assimp reads the file: a PLY's header and
 * counts against the bytes that follow (binary PLY walked element by
 * element, ASCII PLY line by line) and its face indices; numbers in text
 * files of at most CS_MESH_MAX_NUMBER_DIGITS digits. A binary PLY that assimp 5.2
 * would misread (data starting with a line feed) gets a corrected copy in
 * res->data. CS_OK, or CS_ERR_BAD_INPUT with err. */
int cs_mesh_precheck(const char *path, cs_mesh_precheck_result *res, char *err, size_t errlen);

/* What assimp's post-processing would trust in an imported scene: face
 * indices within their mesh, no face without corners or with more than
 * CS_MESH_MAX_CORNERS, node mesh indices in range. */
int cs_mesh_check_scene(const struct aiScene *scene, const char *path, char *err, size_t errlen);

/* ------------------------------------------------------------ repairs */

/* Welds vertices at identical positions, drops zero-area and duplicate
 * triangles and unreferenced vertices (counted in r). NULL: no memory. */
cs_trimesh *cs_mesh_clean(const double *x, int nv, const int *tri, int nt, cs_mesh_report *r);

/* Joins vertices at exactly equal positions: remap[i] is the kept index,
 * kept vertices renumbered from 0 in first-seen order. Returns the count
 * kept, or -1 when memory runs out. */
int cs_mesh_weld(const double *x, int nv, int *remap);

#endif

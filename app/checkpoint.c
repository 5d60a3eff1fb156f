/* checkpoint.c: DIR/state.h5 through HDF5's C API (the definition and
 * state hashes are run_identity.c's; a build without HDF5 compiles
 * checkpoint_none.c instead). */
#include "app/checkpoint.h"

#include "app/run.h"
#include "common/util.h"

#include <errno.h>
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef CS_VERSION
#define CS_VERSION "unknown"
#endif

#define STATE_FORMAT "clothsim state"
enum { STATE_FORMAT_VERSION = 3 }; /* 2: the warm starts' histories; 3: B.5's less B.1's */

/* ------------------------------------------------------------------ HDF5 */

/* HDF5's own error stack goes unprinted: a failed call is reported once, in
 * our words, with errno when the file system set one. */
static void quiet_hdf5(void)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

static hid_t string_type(size_t len)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t >= 0 && (H5Tset_size(t, len > 0 ? len : 1) < 0 || H5Tset_strpad(t, H5T_STR_NULLPAD) < 0)) {
        H5Tclose(t);
        t = -1;
    }
    return t;
}

static int attr_write(hid_t loc, const char *name, hid_t type, const void *value)
{
    hid_t space = H5Screate(H5S_SCALAR);
    hid_t a = space >= 0 ? H5Acreate2(loc, name, type, space, H5P_DEFAULT, H5P_DEFAULT) : -1;
    int rc = a >= 0 && H5Awrite(a, type, value) >= 0 ? 0 : -1;
    if (a >= 0)
        H5Aclose(a);
    if (space >= 0)
        H5Sclose(space);
    return rc;
}

static int attr_string(hid_t loc, const char *name, const char *value)
{
    hid_t t = string_type(strlen(value));
    int rc = t >= 0 ? attr_write(loc, name, t, value) : -1;
    if (t >= 0)
        H5Tclose(t);
    return rc;
}

/* A dataset at path (groups made as needed) of the given shape and types. */
static int dataset_write(hid_t file, const char *path, hid_t file_type, hid_t mem_type,
                         int rank, const hsize_t *dims, const void *data)
{
    hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
    hid_t space = rank > 0 ? H5Screate_simple(rank, dims, NULL) : H5Screate(H5S_SCALAR);
    hid_t d = -1;
    if (lcpl >= 0 && space >= 0 && H5Pset_create_intermediate_group(lcpl, 1) >= 0)
        d = H5Dcreate2(file, path, file_type, space, lcpl, H5P_DEFAULT, H5P_DEFAULT);
    bool empty = rank > 0 && dims[0] == 0; /* nothing to write (no overrides) */
    int rc = d >= 0 && (empty || H5Dwrite(d, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0)
                 ? 0
                 : -1;
    if (d >= 0 && H5Dclose(d) < 0)
        rc = -1;
    if (space >= 0)
        H5Sclose(space);
    if (lcpl >= 0)
        H5Pclose(lcpl);
    return rc;
}

/* count doubles, as rows of 3 when they are particles' vectors */
static int doubles_write(hid_t file, const char *path, const double *data, size_t count)
{
    hsize_t dims[2] = {count, 3};
    int rank = 1;
    if (count > 1 && count % 3 == 0) {
        dims[0] = count / 3;
        rank = 2;
    }
    return dataset_write(file, path, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, rank, dims, data);
}

static int write_contents(hid_t f, const cs_run_identity *id, int frame, const char *state_hash,
                          cs_sim *sim, const double *totals)
{
    int ints[][2] = {{STATE_FORMAT_VERSION, 0}, {frame, 0}, {id->particles, 0},
                     {cs_sim_ranks(sim), 0}, {cs_parallel_threads(), 0}};
    const char *int_names[] = {"format_version", "frame", "particles", "ranks", "threads"};
    double time = cs_sim_time(sim);
    int bad = attr_string(f, "format", STATE_FORMAT) || attr_string(f, "clothsim_version", CS_VERSION) ||
              attr_string(f, "scene_file", id->scene_file) ||
              attr_string(f, "mesh_format", id->format) ||
              attr_string(f, "definition_hash", id->definition_hash) ||
              attr_string(f, "state_hash", state_hash) ||
              attr_write(f, "time", H5T_NATIVE_DOUBLE, &time);
    for (int k = 0; k < 5 && !bad; k++)
        bad = attr_write(f, int_names[k], H5T_NATIVE_INT, &ints[k][0]);

    cs_state_array a[CS_STATE_MAX_ARRAYS];
    int na = cs_sim_state_arrays(sim, a);
    char path[128];
    for (int k = 0; k < na && !bad; k++) {
        snprintf(path, sizeof path, "/state/%s", a[k].name);
        bad = doubles_write(f, path, a[k].data, a[k].count);
    }

    hsize_t one = 1;
    const char *texts[] = {id->scene_text, id->resolved};
    size_t lens[] = {id->scene_len, id->resolved_len};
    const char *names[] = {"/scene/text", "/scene/resolved"};
    for (int k = 0; k < 2; k++) {
        hid_t text = string_type(lens[k]);
        bad = bad || text < 0 || dataset_write(f, names[k], text, text, 0, &one, texts[k]) != 0;
        if (text >= 0)
            H5Tclose(text);
    }
    /* fixed-length strings: variable-length ones go through HDF5's type
     * conversion, which callocs a megabyte per write (most of the cost of
     * a small checkpoint) */
    size_t width = 1;
    for (int i = 0; i < id->noverrides; i++)
        if (strlen(id->overrides[i]) > width)
            width = strlen(id->overrides[i]);
    char *packed = calloc((size_t)id->noverrides + 1, width);
    for (int i = 0; packed && i < id->noverrides; i++)
        memcpy(packed + i * width, id->overrides[i], strlen(id->overrides[i]));
    hid_t fixed = string_type(width);
    hsize_t nover = (hsize_t)id->noverrides;
    bad = bad || !packed || fixed < 0 ||
          dataset_write(f, "/scene/overrides", fixed, fixed, 1, &nover, packed) != 0;
    if (fixed >= 0)
        H5Tclose(fixed);
    free(packed);
    return bad || doubles_write(f, "/run/totals", totals, CS_SUMMARY_TOTALS) != 0 ? -1 : 0;
}

/* HDF5 builds the file in memory (the core driver, no backing store) and
 * the bytes are written here, every write checked. HDF5's own writer would
 * report a full disk at H5Fclose, after which the library still holds the
 * file and crashes closing it again at exit (1.10.8, seen under a file-size
 * limit). The image is taken after an explicit flush: without it 1.10.8
 * hands out object headers not yet written back (an unreadable file). */
const char *cs_checkpoint_file_name(void) { return "state.h5"; }

int cs_checkpoint_write(const char *path, const cs_run_identity *id, int frame,
                        const char *state_hash, cs_sim *sim, const double *totals, char *err,
                        size_t errlen)
{
    quiet_hdf5();
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    hid_t f = -1;
    if (fapl >= 0 && H5Pset_fapl_core(fapl, 1 << 16, 0) >= 0)
        f = H5Fcreate("clothsim-state-in-memory", H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    if (fapl >= 0)
        H5Pclose(fapl);
    ssize_t size = -1;
    char *image = NULL;
    if (f >= 0 && write_contents(f, id, frame, state_hash, sim, totals) == 0 &&
        H5Fflush(f, H5F_SCOPE_GLOBAL) >= 0 && (size = H5Fget_file_image(f, NULL, 0)) > 0 && (image = malloc((size_t)size)) != NULL &&
        H5Fget_file_image(f, image, (size_t)size) != size)
        size = -1;
    if (f >= 0 && H5Fclose(f) < 0)
        size = -1;
    int rc = -1;
    if (size <= 0 || !image)
        snprintf(err, errlen, "cannot write %s: the HDF5 library failed to build it (out of "
                 "memory?)", path);
    else
        rc = cs_file_write_atomic(path, image, (size_t)size, err, errlen);
    free(image);
    return rc;
}

/* ----------------------------------------------------------------- reading */

static int attr_read(hid_t loc, const char *name, hid_t mem_type, void *value)
{
    hid_t a = H5Aexists(loc, name) > 0 ? H5Aopen(loc, name, H5P_DEFAULT) : -1;
    int rc = a >= 0 && H5Aread(a, mem_type, value) >= 0 ? 0 : -1;
    if (a >= 0)
        H5Aclose(a);
    return rc;
}

/* A string attribute into buf (NUL-terminated, cut to len - 1). */
static int attr_read_string(hid_t loc, const char *name, char *buf, size_t len)
{
    hid_t a = H5Aexists(loc, name) > 0 ? H5Aopen(loc, name, H5P_DEFAULT) : -1;
    hid_t ft = a >= 0 ? H5Aget_type(a) : -1;
    size_t size = ft >= 0 && H5Tget_class(ft) == H5T_STRING && !H5Tis_variable_str(ft)
                      ? H5Tget_size(ft)
                      : 0;
    char *raw = size > 0 ? calloc(size + 1, 1) : NULL;
    hid_t mt = raw ? string_type(size) : -1;
    int rc = mt >= 0 && H5Aread(a, mt, raw) >= 0 ? 0 : -1;
    if (rc == 0)
        snprintf(buf, len, "%s", raw);
    free(raw);
    if (mt >= 0)
        H5Tclose(mt);
    if (ft >= 0)
        H5Tclose(ft);
    if (a >= 0)
        H5Aclose(a);
    return rc;
}

/* Exactly count doubles from the dataset at path. */
static int doubles_read(hid_t f, const char *path, double *data, size_t count)
{
    hid_t d = H5Lexists(f, path, H5P_DEFAULT) > 0 ? H5Dopen2(f, path, H5P_DEFAULT) : -1;
    hid_t space = d >= 0 ? H5Dget_space(d) : -1;
    hssize_t n = space >= 0 ? H5Sget_simple_extent_npoints(space) : -1;
    int rc = n >= 0 && (size_t)n == count &&
                     H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0
                 ? 0
                 : -1;
    if (space >= 0)
        H5Sclose(space);
    if (d >= 0)
        H5Dclose(d);
    return rc;
}

/* The fixed-length string dataset at path: *count strings of *width bytes
 * each (NUL-padded), in one malloc'd block with a terminator after it;
 * NULL when missing or of another kind. */
static char *strings_read(hid_t f, const char *path, size_t *count, size_t *width)
{
    hid_t d = H5Lexists(f, path, H5P_DEFAULT) > 0 ? H5Dopen2(f, path, H5P_DEFAULT) : -1;
    hid_t space = d >= 0 ? H5Dget_space(d) : -1;
    hssize_t n = space >= 0 ? H5Sget_simple_extent_npoints(space) : -1;
    hid_t ft = d >= 0 ? H5Dget_type(d) : -1;
    *width = ft >= 0 && H5Tget_class(ft) == H5T_STRING && !H5Tis_variable_str(ft)
                 ? H5Tget_size(ft)
                 : 0;
    *count = n > 0 ? (size_t)n : 0;
    char *raw = n >= 0 && *width > 0 ? calloc(*count * *width + 1, 1) : NULL;
    if (raw && n > 0 && H5Dread(d, ft, H5S_ALL, H5S_ALL, H5P_DEFAULT, raw) < 0) {
        free(raw);
        raw = NULL;
    }
    if (ft >= 0)
        H5Tclose(ft);
    if (space >= 0)
        H5Sclose(space);
    if (d >= 0)
        H5Dclose(d);
    return raw;
}

/* The stored overrides: a malloc'd array of strings, all in one block. */
static int overrides_read(hid_t f, char ***out, int *n)
{
    size_t count, width;
    char *raw = strings_read(f, "/scene/overrides", &count, &width);
    size_t ptrs = sizeof(char *) * (count + 1);
    char **list = raw ? calloc(1, ptrs + count * (width + 1)) : NULL;
    for (size_t i = 0; list && i < count; i++) {
        list[i] = (char *)list + ptrs + i * (width + 1);
        memcpy(list[i], raw + i * width, width); /* NUL-padded, so ends at a NUL */
    }
    free(raw);
    *out = list;
    *n = (int)count;
    return list ? 0 : -1;
}

/* ---------------------------------------------------------- differences */

/* --frames and --set time.frames may change: resuming runs on to another
 * frame count. */
static bool counts_frames(const char *override)
{
    return strncmp(override, "time.frames=", 12) == 0;
}

/* Line number and the two versions of the first line where a and b differ;
 * false when they are the same bytes. */
static bool first_difference(const char *a, size_t alen, const char *b, size_t blen, int *line,
                             char *la, char *lb, size_t len)
{
    if (alen == blen && memcmp(a, b, alen) == 0)
        return false;
    size_t i = 0, start = 0;
    *line = 1;
    while (i < alen && i < blen && a[i] == b[i]) {
        if (a[i] == '\n') {
            (*line)++;
            start = i + 1;
        }
        i++;
    }
    const char *texts[2] = {a, b};
    size_t lens[2] = {alen, blen};
    char *outs[2] = {la, lb};
    for (int k = 0; k < 2; k++) {
        size_t end = start;
        while (end < lens[k] && texts[k][end] != '\n' && texts[k][end] != '\r')
            end++;
        if (start >= lens[k])
            snprintf(outs[k], len, "(end of file)");
        else
            snprintf(outs[k], len, "'%.*s%s'", (int)(end - start > 80 ? 80 : end - start),
                     texts[k] + start, end - start > 80 ? "..." : "");
    }
    return true;
}

/* The overrides other than time.frames: the first of `of` not in `in`. */
static const char *missing_override(const char *const *of, int nof, const char *const *in,
                                    int nin)
{
    for (int i = 0; i < nof; i++) {
        if (counts_frames(of[i]))
            continue;
        bool found = false;
        for (int j = 0; j < nin && !found; j++)
            found = strcmp(of[i], in[j]) == 0;
        if (!found)
            return of[i];
    }
    return NULL;
}

static bool same_override_order(const char *const *a, int na, const char *const *b, int nb)
{
    int i = 0, j = 0;
    for (;;) {
        while (i < na && counts_frames(a[i]))
            i++;
        while (j < nb && counts_frames(b[j]))
            j++;
        if (i == na || j == nb)
            return i == na && j == nb;
        if (strcmp(a[i++], b[j++]) != 0)
            return false;
    }
}

/* Names the first way the stored run differs from id; 0 when it does not. */
static int compare_identity(hid_t f, const char *path, const cs_run_identity *id, char *err,
                            size_t errlen)
{
    int particles = -1;
    char format[16] = "", definition[CS_STATE_HASH_LEN] = "";
    attr_read(f, "particles", H5T_NATIVE_INT, &particles);
    attr_read_string(f, "mesh_format", format, sizeof format);
    attr_read_string(f, "definition_hash", definition, sizeof definition);
    size_t one, width;
    char *text = strings_read(f, "/scene/text", &one, &width);
    size_t len = text ? strnlen(text, width) : 0; /* the padding is not the scene's */
    char **over = NULL;
    int nover = 0;
    if (!text || overrides_read(f, &over, &nover) != 0) {
        snprintf(err, errlen, "%s: the scene the run came from cannot be read", path);
        free(text);
        return CS_EXIT_OUTPUT;
    }
    int line = 0;
    char now[128], then[128], scene_file[1024] = "";
    attr_read_string(f, "scene_file", scene_file, sizeof scene_file);
    /* the resolved scenes tell whether the run is the same (a run folder's
     * scene.yaml against the file and overrides it came from); a state
     * written before them has none, and the file and overrides decide */
    size_t width2;
    char *resolved = strings_read(f, "/scene/resolved", &one, &width2);
    size_t rlen = resolved ? strnlen(resolved, width2) : 0;
    bool same_resolved = resolved && id->resolved &&
                         !first_difference(id->resolved, id->resolved_len, resolved, rlen, &line,
                                           now, then, sizeof now);
    bool same_file = !resolved || (!id->own_scene && strcmp(scene_file, id->scene_file) == 0);
    const char *gone = missing_override((const char *const *)over, nover, id->overrides,
                                        id->noverrides);
    const char *added = missing_override(id->overrides, id->noverrides,
                                         (const char *const *)over, nover);
    int rc = CS_EXIT_INPUT;
    if (same_resolved)
        gone = added = NULL;
    if (!same_resolved && !same_file)
        snprintf(err, errlen, "cannot resume from %s: %s:%d: the resolved scene differs from "
                 "the run's: now %s, then %s", path, id->scene_file, line, now, then);
    else if (!same_resolved &&
             first_difference(id->scene_text, id->scene_len, text, len, &line, now, then,
                              sizeof now))
        snprintf(err, errlen, "cannot resume from %s: %s:%d: the scene file changed since the "
                 "run began: now %s, then %s", path, id->scene_file, line, now, then);
    else if (gone)
        snprintf(err, errlen, "cannot resume from %s: the run began with --set %s, which is "
                 "not given now", path, gone);
    else if (added)
        snprintf(err, errlen, "cannot resume from %s: --set %s was not given when the run "
                 "began", path, added);
    else if (!same_resolved && !same_override_order(id->overrides, id->noverrides,
                                                    (const char *const *)over, nover))
        snprintf(err, errlen, "cannot resume from %s: the --set overrides are given in another "
                 "order than when the run began (a later one wins)", path);
    else if (strcmp(format, id->format) != 0)
        snprintf(err, errlen, "cannot resume from %s: the frames are %s files, not %s (give "
                 "--format %s)", path, format, id->format, format);
    else if (particles != id->particles)
        snprintf(err, errlen, "cannot resume from %s: the scene now has %d particles, the run "
                 "had %d", path, id->particles, particles);
    else if (strcmp(definition, id->definition_hash) != 0)
        snprintf(err, errlen, "cannot resume from %s: the scene's initial state (positions, "
                 "velocities, masses, step or a body's mesh) differs from the run's although "
                 "its text and overrides do not: did a mesh file it reads change?", path);
    else if (!same_resolved && resolved && id->resolved &&
             first_difference(id->resolved, id->resolved_len, resolved, rlen, &line, now, then,
                              sizeof now))
        snprintf(err, errlen, "cannot resume from %s: the resolved scene differs from the "
                 "run's at line %d: now %s, then %s", path, line, now, then);
    else
        rc = 0;
    free(resolved);
    free(text);
    free(over);
    return rc;
}

/* Opens path as a state file of this format version into *f; what
 * ("resume", "start from it") words the refusals. */
static int state_open(const char *path, const char *what, hid_t *f, char *err, size_t errlen)
{
    quiet_hdf5();
    FILE *probe = fopen(path, "rb");
    if (!probe) {
        if (errno == ENOENT)
            snprintf(err, errlen, "cannot %s: there is no %s (a run writes it after each "
                     "frame)", what, path);
        else
            snprintf(err, errlen, "cannot read %s: %s", path, strerror(errno));
        return errno == ENOENT ? CS_EXIT_INPUT : CS_EXIT_OUTPUT;
    }
    fclose(probe);
    *f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    char kind[32] = "";
    int version = 0;
    if (*f < 0 || attr_read_string(*f, "format", kind, sizeof kind) != 0 ||
        strcmp(kind, STATE_FORMAT) != 0 ||
        attr_read(*f, "format_version", H5T_NATIVE_INT, &version) != 0) {
        snprintf(err, errlen, "cannot %s: %s is not a clothsim state file", what, path);
        if (*f >= 0)
            H5Fclose(*f);
        return CS_EXIT_INPUT;
    }
    if (version != STATE_FORMAT_VERSION) {
        snprintf(err, errlen, "cannot %s: %s is a state file of format version %d; this "
                 "clothsim reads version %d", what, path, version, STATE_FORMAT_VERSION);
        H5Fclose(*f);
        return CS_EXIT_INPUT;
    }
    return CS_EXIT_OK;
}

/* The dataset at path as a malloc'd array of *count doubles (NULL, 0 when
 * it is missing or empty). */
static double *doubles_read_all(hid_t f, const char *path, size_t *count)
{
    hid_t d = H5Lexists(f, path, H5P_DEFAULT) > 0 ? H5Dopen2(f, path, H5P_DEFAULT) : -1;
    hid_t space = d >= 0 ? H5Dget_space(d) : -1;
    hssize_t n = space >= 0 ? H5Sget_simple_extent_npoints(space) : -1;
    double *data = n > 0 ? malloc(sizeof *data * (size_t)n) : NULL;
    if (data && H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
        free(data);
        data = NULL;
    }
    *count = data ? (size_t)n : 0;
    if (space >= 0)
        H5Sclose(space);
    if (d >= 0)
        H5Dclose(d);
    return data;
}

int cs_checkpoint_read_start(const char *path, cs_start_state *st, char *err, size_t errlen)
{
    memset(st, 0, sizeof *st);
    hid_t f;
    int rc = state_open(path, "start from it", &f, err, errlen);
    if (rc != CS_EXIT_OK)
        return rc;
    size_t nx = 0, nv = 0, nlag = 0;
    if (attr_read(f, "frame", H5T_NATIVE_INT, &st->frame) != 0 ||
        attr_read(f, "particles", H5T_NATIVE_INT, &st->particles) != 0 ||
        attr_read(f, "time", H5T_NATIVE_DOUBLE, &st->time) != 0 || st->particles < 1 ||
        !(st->x = doubles_read_all(f, "/state/positions", &nx)) ||
        !(st->v = doubles_read_all(f, "/state/velocities", &nv)) ||
        nx != 3 * (size_t)st->particles || nv != nx) {
        snprintf(err, errlen, "cannot start from %s: it lacks the frame, the time or the "
                 "positions and velocities of its particles", path);
        rc = CS_EXIT_OUTPUT;
    }
    st->lag = rc == CS_EXIT_OK ? doubles_read_all(f, "/state/scripts/lag", &nlag) : NULL;
    st->nlag = (int)nlag;
    H5Fclose(f);
    if (rc != CS_EXIT_OK)
        cs_start_state_free(st);
    return rc;
}

void cs_start_state_free(cs_start_state *st)
{
    free(st->x);
    free(st->v);
    free(st->lag);
    memset(st, 0, sizeof *st);
}

int cs_checkpoint_read(const char *path, const cs_run_identity *id, cs_sim *sim, int *frame,
                       double *totals, char *err, size_t errlen)
{
    hid_t f;
    int rc = state_open(path, "resume", &f, err, errlen);
    if (rc != CS_EXIT_OK)
        return rc;
    rc = compare_identity(f, path, id, err, errlen);
    char stored_hash[CS_STATE_HASH_LEN] = "";
    if (rc == 0 && (attr_read(f, "frame", H5T_NATIVE_INT, frame) != 0 ||
                    attr_read_string(f, "state_hash", stored_hash, sizeof stored_hash) != 0 ||
                    doubles_read(f, "/run/totals", totals, CS_SUMMARY_TOTALS) != 0)) {
        snprintf(err, errlen, "cannot resume: %s lacks the frame, its hash or the run's totals",
                 path);
        rc = CS_EXIT_OUTPUT;
    }
    cs_state_array a[CS_STATE_MAX_ARRAYS];
    int na = cs_sim_state_arrays(sim, a);
    char name[128];
    for (int k = 0; k < na && rc == 0; k++) {
        snprintf(name, sizeof name, "/state/%s", a[k].name);
        if (doubles_read(f, name, a[k].data, a[k].count) != 0) {
            snprintf(err, errlen, "cannot resume: %s lacks %s of %zu values", path, name,
                     a[k].count);
            rc = CS_EXIT_OUTPUT;
        }
    }
    int ranks = 0;
    if (rc == 0 && attr_read(f, "ranks", H5T_NATIVE_INT, &ranks) == 0 &&
        ranks != cs_sim_ranks(sim)) /* allowed: the state is whole, the partition new */
        fprintf(stderr, "clothsim: note: the run began on %d rank%s and resumes on %d: from "
                "here its frames are those of neither rank count bit for bit\n", ranks,
                ranks == 1 ? "" : "s", cs_sim_ranks(sim));
    H5Fclose(f);
    char hash[CS_STATE_HASH_LEN];
    if (rc == 0) { /* the file's own check: the state read is the state written */
        cs_state_hash(sim, hash);
        if (strcmp(hash, stored_hash) != 0) {
            snprintf(err, errlen, "cannot resume: %s is damaged (its state hashes to %s, "
                     "written as %s)", path, hash, stored_hash);
            rc = CS_EXIT_OUTPUT;
        }
    }
    return rc;
}

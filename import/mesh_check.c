/* mesh_check.c: what a mesh file claims, checked before assimp trusts it.
 *
 * assimp 5.2's PLY reader believes its header: a count of 1e20 vertices
 * loops for a minute, counts of 2^31 to 4e9 vertices, faces or list entries
 * are allocated, a header without end_header loops forever, and face
 * indices out of range crash the post-processing. This is not a PLY reader:
 * it walks the header and the data's layout (binary: element by element;
 * ASCII: line by line, as assimp reads it) checking counts against the
 * bytes that are there, face indices against the vertex count and corners
 * against CS_MESH_MAX_CORNERS, and leaves the values to assimp. Text files
 * of any format are scanned for absurdly long numbers. After assimp has
 * read a file, and before any post-processing step, cs_mesh_check_scene
 * checks every format's faces the same way.
 *
 * It also works around assimp issue #5692: its binary PLY reader drops the
 * first data byte when it is a line feed (0x0A; one float in 256 begins so)
 * after a header ending in "\n", shifting everything after. Such a file is
 * handed to assimp from memory with its header ending in "\r\n" instead,
 * which 5.2 reads right and so do later versions. (An extra one-byte
 * element before the data does not work: 5.2 counts 0 instances of an
 * element whose name it does not know.) Fixing it on the reading side
 * rather than writing frames whose first byte is never 0x0A also reads the
 * frames earlier versions wrote and PLY files from other programs.
 */
#include "import/mesh_internal.h"

#include <assimp/scene.h>

#include <ctype.h>
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#define HEADER_MAX (1 << 20)   /* a PLY header is a few hundred bytes */
#define MAX_ELEMENTS 64
#define MAX_PROPS 64

/* ------------------------------------------------------------ PLY header */

typedef enum ply_type { T_BAD = 0, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 } ply_type;

static const struct {
    const char *a, *b;
    int size;
} TYPES[] = {
    [T_I8] = {"char", "int8", 1},     [T_U8] = {"uchar", "uint8", 1},
    [T_I16] = {"short", "int16", 2},  [T_U16] = {"ushort", "uint16", 2},
    [T_I32] = {"int", "int32", 4},    [T_U32] = {"uint", "uint32", 4},
    [T_F32] = {"float", "float32", 4}, [T_F64] = {"double", "float64", 8},
};

static ply_type type_named(const char *s)
{
    for (int t = T_I8; t <= T_F64; t++)
        if (!strcmp(s, TYPES[t].a) || !strcmp(s, TYPES[t].b))
            return (ply_type)t;
    return T_BAD;
}

typedef struct ply_prop {
    ply_type type;
    ply_type count_type;     /* T_BAD: not a list */
    bool indices;            /* a face's vertex_indices */
} ply_prop;

typedef struct ply_elem {
    char name[64];
    unsigned long long count;
    int nprops;
    ply_prop props[MAX_PROPS];
} ply_elem;

typedef struct ply_header {
    enum { PLY_ASCII, PLY_LE, PLY_BE } format;
    int nelems;
    ply_elem elems[MAX_ELEMENTS];
    size_t length;           /* bytes up to and with end_header's line end */
    bool crlf;               /* end_header ends with \r\n */
    int lines;               /* lines in the header */
    unsigned long long vertices;
} ply_header;

typedef struct checker {
    const char *path;
    char *err;
    size_t errlen;
} checker;

#define FAIL(c, ...)                                                     \
    do {                                                                 \
        char why_[512];                                                  \
        snprintf(why_, sizeof why_, __VA_ARGS__);                        \
        cs_mesh_set_err((c)->err, (c)->errlen, "%s: %s", (c)->path, why_); \
        return CS_ERR_BAD_INPUT;                                      \
    } while (0)

/* The next whitespace-separated word of *s, NUL-terminated in place. */
static char *word(char **s)
{
    char *p = *s;
    while (*p == ' ' || *p == '\t')
        p++;
    if (!*p)
        return NULL;
    char *start = p;
    while (*p && *p != ' ' && *p != '\t')
        p++;
    if (*p)
        *p++ = '\0';
    *s = p;
    return start;
}

static int parse_property(checker *c, ply_header *h, char *rest, int line)
{
    if (h->nelems == 0)
        return CS_OK;   /* assimp ignores it too */
    ply_elem *e = &h->elems[h->nelems - 1];
    if (e->nprops == MAX_PROPS)
        FAIL(c, "PLY header line %d: element '%s' has more than %d properties", line, e->name,
             MAX_PROPS);
    ply_prop *p = &e->props[e->nprops];
    char *t = word(&rest), *name;
    if (t && !strcmp(t, "list")) {
        char *ct = word(&rest), *it = word(&rest);
        name = word(&rest);
        p->count_type = ct ? type_named(ct) : T_BAD;
        p->type = it ? type_named(it) : T_BAD;
        if (!name || p->count_type == T_BAD || p->type == T_BAD || p->count_type == T_F32 ||
            p->count_type == T_F64)
            FAIL(c, "PLY header line %d: a list property needs an integer count type, a value "
                 "type and a name", line);
    } else {
        name = word(&rest);
        p->type = t ? type_named(t) : T_BAD;
        if (!name || p->type == T_BAD)
            FAIL(c, "PLY header line %d: unknown property type '%.40s'", line, t ? t : "");
    }
    p->indices = p->count_type != T_BAD && !strcmp(e->name, "face") &&
                 (!strcmp(name, "vertex_indices") || !strcmp(name, "vertex_index"));
    e->nprops++;
    return CS_OK;
}

/* Parses the header in buf (n bytes, the start of the file). */
static int parse_header(checker *c, char *buf, size_t n, ply_header *h)
{
    memset(h, 0, sizeof *h);
    size_t pos = 0;
    bool have_format = false;
    for (int line = 1; pos < n; line++) {
        char *nl = memchr(buf + pos, '\n', n - pos);
        if (!nl)
            break;
        size_t start = pos, len = (size_t)(nl - (buf + pos));
        pos += len + 1;
        bool cr = len > 0 && buf[start + len - 1] == '\r';
        buf[start + len - cr] = '\0';
        char *s = buf + start, *kw = word(&s);
        if (!kw || line == 1)
            continue;   /* the magic, checked by the caller */
        if (!strcmp(kw, "format")) {
            char *f = word(&s);
            if (f && !strcmp(f, "ascii"))
                h->format = PLY_ASCII;
            else if (f && !strcmp(f, "binary_little_endian"))
                h->format = PLY_LE;
            else if (f && !strcmp(f, "binary_big_endian"))
                h->format = PLY_BE;
            else
                FAIL(c, "PLY header line %d: unknown format '%.40s'", line, f ? f : "");
            have_format = true;
        } else if (!strcmp(kw, "element")) {
            char *name = word(&s), *count = word(&s);
            if (h->nelems == MAX_ELEMENTS)
                FAIL(c, "PLY header has more than %d elements", MAX_ELEMENTS);
            if (!name || !count || !isdigit((unsigned char)count[0]))
                FAIL(c, "PLY header line %d: expected 'element NAME COUNT'", line);
            for (int k = 0; k < h->nelems; k++) /* assimp aborts on a repeat (found by fuzzing) */
                if (!strcmp(h->elems[k].name, name))
                    FAIL(c, "PLY header line %d: element '%.40s' is declared twice", line, name);
            ply_elem *e = &h->elems[h->nelems++];
            snprintf(e->name, sizeof e->name, "%s", name);
            errno = 0;
            char *end;
            e->count = strtoull(count, &end, 10);
            if (*end || errno == ERANGE)
                FAIL(c, "PLY header line %d: element %s: count '%.40s' is not a whole number "
                     "below 2^64", line, e->name, count);
            if (!strcmp(e->name, "vertex"))
                h->vertices = e->count;
        } else if (!strcmp(kw, "property")) {
            int rc = parse_property(c, h, s, line);
            if (rc)
                return rc;
        } else if (!strcmp(kw, "end_header")) {
            if (!have_format)
                FAIL(c, "PLY header has no format line");
            h->length = pos;
            h->crlf = cr;
            h->lines = line;
            return CS_OK;
        }
    }
    if (n >= HEADER_MAX)
        FAIL(c, "PLY header has no end_header line in its first %d bytes", HEADER_MAX);
    FAIL(c, "PLY header has no end_header line (the file is truncated or not a PLY file)");
}

/* Checks each element's count against the bytes after the header: an
 * instance takes at least its fixed-size properties and list counts
 * (binary), or a character and a separator per property (ASCII). */
static int check_counts(checker *c, const ply_header *h, unsigned long long data_bytes)
{
    double need = 0;
    for (int i = 0; i < h->nelems; i++) {
        const ply_elem *e = &h->elems[i];
        int least = 0;
        for (int k = 0; k < e->nprops; k++) {
            const ply_prop *p = &e->props[k];
            if (h->format == PLY_ASCII)
                least += 2;
            else
                least += TYPES[p->count_type != T_BAD ? p->count_type : p->type].size;
        }
        if (least == 0)
            least = 1;   /* an element of no properties is at least a line */
        need += (double)e->count * least;
        if (need > (double)data_bytes + 1)
            FAIL(c, "the PLY header promises %llu '%s' elements (at least %.0f bytes with those "
                 "before them) but only %llu bytes follow the header",
                 e->count, e->name, need, data_bytes);
        if (!strcmp(e->name, "tristrips") && e->count > 0)
            FAIL(c, "triangle strips (element 'tristrips') are not read by assimp's PLY reader, "
                 "which would keep one triangle of them; convert them to faces (e.g. in MeshLab "
                 "or Blender)");
    }
    return CS_OK;
}

/* ------------------------------------------------------------ PLY data */

typedef struct data_walk {
    checker *c;
    const ply_header *h;
    FILE *f;
    unsigned long long left;   /* bytes not yet read */
} data_walk;

static bool read_bytes(data_walk *w, void *out, size_t n)
{
    if (n > w->left || fread(out, 1, n, w->f) != n)
        return false;
    w->left -= n;
    return true;
}

/* A binary integer of type t; false at the end of the file. */
static bool read_int(data_walk *w, ply_type t, long long *v)
{
    unsigned char b[8];
    int n = TYPES[t].size;
    if (!read_bytes(w, b, (size_t)n))
        return false;
    unsigned long long u = 0;
    for (int i = 0; i < n; i++)
        u |= (unsigned long long)b[w->h->format == PLY_BE ? n - 1 - i : i] << (8 * i);
    switch (t) {
    case T_I8: *v = (int8_t)u; break;
    case T_I16: *v = (int16_t)u; break;
    case T_I32: *v = (int32_t)u; break;
    case T_F32: {
        uint32_t bits = (uint32_t)u;
        float x;
        memcpy(&x, &bits, sizeof x);
        *v = x >= -9e18f && x <= 9e18f ? (long long)x : -1;
        break;
    }
    case T_F64: {
        double x;
        memcpy(&x, &u, sizeof x);
        *v = x >= -9e18 && x <= 9e18 ? (long long)x : -1;
        break;
    }
    default: *v = (long long)u; break;
    }
    return true;
}

static int check_face_index(checker *c, const ply_header *h, unsigned long long face,
                            long long index)
{
    if (index < 0 || (unsigned long long)index >= h->vertices)
        FAIL(c, "PLY face %llu refers to vertex %lld, but the file has %llu vertices", face,
             index, h->vertices);
    return CS_OK;
}

static int check_corners(checker *c, unsigned long long face, long long n)
{
    if (n > CS_MESH_MAX_CORNERS)
        FAIL(c, "PLY face %llu has %lld corners; at most %d are read (triangulating a polygon "
             "takes time growing with the square of its corners)", face, n, CS_MESH_MAX_CORNERS);
    return CS_OK;
}

#define TRUNCATED(w, e, i)                                                                  \
    FAIL((w)->c, "the file ends in %s %llu of the %llu its PLY header promises (truncated?)", \
         (e)->name, (unsigned long long)(i), (e)->count)

static int walk_binary(data_walk *w)
{
    for (int ei = 0; ei < w->h->nelems; ei++) {
        const ply_elem *e = &w->h->elems[ei];
        bool fixed = true;
        long long record = 0;
        for (int k = 0; k < e->nprops; k++) {
            fixed = fixed && e->props[k].count_type == T_BAD;
            record += TYPES[e->props[k].type].size;
        }
        if (fixed) {   /* vertices: only the size matters */
            double bytes = (double)record * (double)e->count;
            if (bytes > (double)w->left)
                TRUNCATED(w, e, w->left / (unsigned long long)(record ? record : 1));
            if (fseeko(w->f, (off_t)bytes, SEEK_CUR) != 0)
                FAIL(w->c, "cannot read it: %s", strerror(errno));
            w->left -= (unsigned long long)bytes;
            continue;
        }
        for (unsigned long long i = 0; i < e->count; i++)
            for (int k = 0; k < e->nprops; k++) {
                const ply_prop *p = &e->props[k];
                long long n, v;
                if (p->count_type == T_BAD) {
                    unsigned char skip[8];
                    if (!read_bytes(w, skip, (size_t)TYPES[p->type].size))
                        TRUNCATED(w, e, i);
                    continue;
                }
                if (!read_int(w, p->count_type, &n))
                    TRUNCATED(w, e, i);
                if (n < 0)
                    FAIL(w->c, "PLY %s %llu has a list of %lld entries", e->name, i, n);
                if ((double)n * TYPES[p->type].size > (double)w->left)
                    FAIL(w->c, "PLY %s %llu has a list of %lld entries, more than the %llu "
                         "bytes left in the file", e->name, i, n, w->left);
                if (p->indices && check_corners(w->c, i, n))
                    return CS_ERR_BAD_INPUT;
                for (long long j = 0; j < n; j++) {
                    if (!read_int(w, p->type, &v))
                        TRUNCATED(w, e, i);
                    if (p->indices && check_face_index(w->c, w->h, i, v))
                        return CS_ERR_BAD_INPUT;
                }
            }
    }
    return CS_OK;
}

static int check_number(checker *c, const char *tok, long line)
{
    size_t digits = 0;
    for (const char *p = tok; *p; p++)
        digits += isdigit((unsigned char)*p) != 0;
    if (digits > CS_MESH_MAX_NUMBER_DIGITS)
        FAIL(c, "line %ld: a number of %zu digits (at most %d are read)", line, digits,
             CS_MESH_MAX_NUMBER_DIGITS);
    return CS_OK;
}

/* The next line that holds something, its line end removed; NULL at the
 * end of the file. */
static char *next_line(data_walk *w, char **line, size_t *cap, long *lineno)
{
    for (;;) {
        ssize_t got = getline(line, cap, w->f);
        if (got <= 0)
            return NULL;
        (*lineno)++;
        while (got > 0 && ((*line)[got - 1] == '\n' || (*line)[got - 1] == '\r'))
            (*line)[--got] = '\0';
        char *p = *line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p)
            return p;
    }
}

static long long count_words(const char *s)
{
    long long n = 0;
    while (*s) {
        while (*s == ' ' || *s == '\t')
            s++;
        n += *s != '\0';
        while (*s && *s != ' ' && *s != '\t')
            s++;
    }
    return n;
}

/* One list of an ASCII instance: assimp allocates it from its count before
 * reading it, so the count must be what the line holds. */
static int ascii_list(data_walk *w, const ply_elem *e, const ply_prop *p, unsigned long long i,
                      const char *count, char **s, long lineno)
{
    char *stop;
    errno = 0;
    long long n = strtoll(count, &stop, 10), avail = count_words(*s);
    if (*stop || errno == ERANGE || n < 0 || n > avail)
        FAIL(w->c, "line %ld: PLY %s %llu has a list of '%.40s' entries but %lld values follow "
             "on its line", lineno, e->name, i, count, avail);
    if (p->indices && check_corners(w->c, i, n))
        return CS_ERR_BAD_INPUT;
    for (long long j = 0; j < n; j++) {
        char *tok = word(s);
        if (check_number(w->c, tok, lineno))
            return CS_ERR_BAD_INPUT;
        if (!p->indices)
            continue;
        errno = 0;
        long long v = strtoll(tok, &stop, 10);
        if (*stop || errno == ERANGE)
            FAIL(w->c, "line %ld: PLY face %llu has a vertex index '%.40s' that is not a whole "
                 "number", lineno, i, tok);
        if (check_face_index(w->c, w->h, i, v))
            return CS_ERR_BAD_INPUT;
    }
    return CS_OK;
}

/* ASCII PLY as assimp reads it: an instance per line. Values missing at a
 * line's end are left to assimp (it takes zeros). */
static int walk_ascii(data_walk *w, long lineno)
{
    char *line = NULL;
    size_t cap = 0;
    int rc = CS_OK;
    for (int ei = 0; ei < w->h->nelems && !rc; ei++) {
        const ply_elem *e = &w->h->elems[ei];
        for (unsigned long long i = 0; i < e->count && !rc; i++) {
            char *s = next_line(w, &line, &cap, &lineno), *tok;
            if (!s) {
                cs_mesh_set_err(w->c->err, w->c->errlen, "%s: the file ends in %s %llu of the "
                                "%llu its PLY header promises (truncated?)",
                                w->c->path, e->name, i, e->count);
                rc = CS_ERR_BAD_INPUT;
                break;
            }
            for (int k = 0; k < e->nprops && !rc && (tok = word(&s)); k++) {
                rc = check_number(w->c, tok, lineno);
                if (!rc && e->props[k].count_type != T_BAD)
                    rc = ascii_list(w, e, &e->props[k], i, tok, &s, lineno);
            }
            while (!rc && (tok = word(&s)))   /* values beyond the properties */
                rc = check_number(w->c, tok, lineno);
        }
    }
    free(line);
    return rc;
}

/* ------------------------------------------------------------ PLY file */

/* A copy of the file whose header ends in "\r\n": assimp 5.2 then drops
 * the "\n" of the header instead of the data's first byte, and readers
 * that handle line ends properly (assimp since the fix of #5692, every
 * other) read it as the same file. */
static int crlf_copy(checker *c, FILE *f, size_t size, const ply_header *h,
                     cs_mesh_precheck_result *res)
{
    if (size > 0xFFFFFFF0u)
        FAIL(c, "the file is too large to read (4 GB at most)");
    unsigned char *out = malloc(size + 1);
    if (!out) {
        cs_mesh_set_err(c->err, c->errlen, "%s: out of memory", c->path);
        return CS_ERR_NOMEM;
    }
    size_t head = h->length - 1;   /* up to end_header's "\n" */
    rewind(f);
    if (fread(out, 1, head, f) != head || fgetc(f) != '\n' ||
        fread(out + head + 2, 1, size - head - 1, f) != size - head - 1) {
        free(out);
        FAIL(c, "cannot read it: the file changed while it was read");
    }
    out[head] = '\r';
    out[head + 1] = '\n';
    res->data = out;
    res->len = size + 1;
    res->hint = "ply";
    return CS_OK;
}

static int check_ply(checker *c, FILE *f, size_t size, cs_mesh_precheck_result *res)
{
    size_t want = size < HEADER_MAX ? size : HEADER_MAX;
    char *buf = malloc(want + 1);
    ply_header *h = malloc(sizeof *h);
    int rc = CS_ERR_NOMEM;
    if (!buf || !h) {
        cs_mesh_set_err(c->err, c->errlen, "%s: out of memory", c->path);
        goto done;
    }
    rewind(f);
    size_t got = fread(buf, 1, want, f);
    buf[got] = '\0';
    if ((rc = parse_header(c, buf, got, h)) || (rc = check_counts(c, h, size - h->length)))
        goto done;
    if (fseeko(f, (off_t)h->length, SEEK_SET) != 0) {
        cs_mesh_set_err(c->err, c->errlen, "cannot read %s: %s", c->path, strerror(errno));
        rc = CS_ERR_BAD_INPUT;
        goto done;
    }
    data_walk w = {c, h, f, size - h->length};
    rc = h->format == PLY_ASCII ? walk_ascii(&w, h->lines) : walk_binary(&w);
    if (rc)
        goto done;
    int first = EOF;
    if (h->format != PLY_ASCII && !h->crlf && fseeko(f, (off_t)h->length, SEEK_SET) == 0)
        first = fgetc(f);
    if (first == '\n')
        rc = crlf_copy(c, f, size, h, res);
done:
    free(buf);
    free(h);
    return rc;
}

/* ------------------------------------------------------- text numbers */

/* Runs of digits (with signs, points and exponents) longer than any
 * number: a coordinate with a million digits is not a mesh. */
static int scan_numbers(checker *c, FILE *f)
{
    unsigned char buf[65536];
    size_t n, digits = 0;
    long line = 1;
    rewind(f);
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        for (size_t i = 0; i < n; i++) {
            int ch = buf[i];
            if (isdigit(ch)) {
                if (++digits > CS_MESH_MAX_NUMBER_DIGITS)
                    FAIL(c, "line %ld: a number of more than %d digits", line,
                         CS_MESH_MAX_NUMBER_DIGITS);
            } else if (ch != '.' && ch != '+' && ch != '-' && ch != 'e' && ch != 'E') {
                digits = 0;
                line += ch == '\n';
            }
        }
    return CS_OK;
}

static bool has_extension(const char *path, const char *ext)
{
    const char *dot = strrchr(path, '.');
    return dot && !strcasecmp(dot + 1, ext);
}

int cs_mesh_precheck(const char *path, cs_mesh_precheck_result *res, char *err, size_t errlen)
{
    memset(res, 0, sizeof *res);
    checker c = {path, err, errlen};
    FILE *f = fopen(path, "rb");
    struct stat st;
    if (!f || fstat(fileno(f), &st) != 0) {
        cs_mesh_set_err(err, errlen, "cannot read %s: %s", path, strerror(errno));
        if (f)
            fclose(f);
        return CS_ERR_BAD_INPUT;
    }
    unsigned char head[4096];
    size_t n = fread(head, 1, sizeof head, f);
    /* assimp takes any file that starts with "ply" for a PLY file; with
     * anything but a line end after it, its reader crashed or looped
     * (found by fuzzing: "plyR", "ply@") */
    if (n >= 3 && !strncasecmp((const char *)head, "ply", 3) &&
        (n == 3 || (head[3] != '\n' && head[3] != '\r'))) {
        fclose(f);
        cs_mesh_set_err(err, errlen,
                        "cannot read %s: it starts like a PLY file but its first line is not "
                        "'ply'", path);
        return CS_ERR_BAD_INPUT;
    }
    if (n >= 4 && !strncasecmp((const char *)head, "ply", 3))
        res->kind = CS_KIND_PLY;
    else if ((n >= 4 && !memcmp(head, "glTF", 4)) || has_extension(path, "gltf"))
        res->kind = CS_KIND_GLTF;
    else if (has_extension(path, "obj"))
        res->kind = CS_KIND_OBJ;
    int rc = CS_OK;
    if (res->kind == CS_KIND_PLY)
        rc = check_ply(&c, f, (size_t)st.st_size, res);
    else if (!memchr(head, 0, n))   /* text */
        rc = scan_numbers(&c, f);
    fclose(f);
    return rc;
}

/* ------------------------------------------------- the imported scene */

static int check_nodes(checker *c, const struct aiScene *scene, const struct aiNode *node,
                       int depth)
{
    if (depth > 256)
        FAIL(c, "its node tree is deeper than 256 levels");
    for (unsigned i = 0; i < node->mNumMeshes; i++)
        if (!node->mMeshes || node->mMeshes[i] >= scene->mNumMeshes)
            FAIL(c, "node '%.60s' refers to mesh %u of %u", node->mName.data,
                 node->mMeshes ? node->mMeshes[i] : 0, scene->mNumMeshes);
    for (unsigned i = 0; i < node->mNumChildren; i++) {
        if (!node->mChildren || !node->mChildren[i])
            FAIL(c, "node '%.60s' has a missing child", node->mName.data);
        int rc = check_nodes(c, scene, node->mChildren[i], depth + 1);
        if (rc)
            return rc;
    }
    return CS_OK;
}

/* Our own check rather than assimp's aiProcess_ValidateDataStructure,
 * which refuses a mesh without faces: a point cloud, as a frame of a cloth
 * without triangles is. */
int cs_mesh_check_scene(const struct aiScene *scene, const char *path, char *err, size_t errlen)
{
    checker c = {path, err, errlen};
    if (scene->mNumMeshes && !scene->mMeshes)
        FAIL(&c, "its meshes are missing");
    for (unsigned m = 0; m < scene->mNumMeshes; m++) {
        const struct aiMesh *mesh = scene->mMeshes[m];
        if (!mesh || (mesh->mNumVertices && !mesh->mVertices) ||
            (mesh->mNumFaces && !mesh->mFaces))
            FAIL(&c, "mesh %u is incomplete", m);
        for (unsigned f = 0; f < mesh->mNumFaces; f++) {
            const struct aiFace *face = &mesh->mFaces[f];
            if (face->mNumIndices == 0 || !face->mIndices)
                FAIL(&c, "face %u of mesh %u has no corners", f, m);
            if (face->mNumIndices > CS_MESH_MAX_CORNERS)
                FAIL(&c, "face %u of mesh %u has %u corners; at most %d are read (triangulating "
                     "a polygon takes time growing with the square of its corners)",
                     f, m, face->mNumIndices, CS_MESH_MAX_CORNERS);
            for (unsigned k = 0; k < face->mNumIndices; k++)
                if (face->mIndices[k] >= mesh->mNumVertices)
                    FAIL(&c, "face %u of mesh %u refers to vertex %lld, but the mesh has %u "
                         "vertices", f, m,
                         face->mIndices[k] > INT32_MAX ? (long long)(int32_t)face->mIndices[k]
                                                       : (long long)face->mIndices[k],
                         mesh->mNumVertices);
        }
    }
    return scene->mRootNode ? check_nodes(&c, scene, scene->mRootNode, 0) : CS_OK;
}

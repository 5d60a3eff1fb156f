/* mesh_io.c: triangle meshes to and from files through assimp's C API.
 *
 * Writing builds an aiScene by hand (one aiMesh per view, each in its own
 * child node of one root node and named like the view; one empty material
 * because several exporters index mMaterials; area-weighted normals) and
 * hands it to aiExportScene. Assimp copies the scene before touching it, so
 * the scene here is allocated and freed with malloc/free, never by assimp.
 *
 * Reading (cs_mesh_read, in mesh_import.c) merges every mesh instance of
 * the node tree, node transforms applied, into one cs_trimesh.
 */
#include "import/mesh_internal.h"

#include "common/util.h"

#include <assimp/cexport.h>
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

/* ------------------------------------------------------------- messages */

#define set_err cs_mesh_set_err

/* -------------------------------------------------------------- formats */

/* aiExportScene's format id of each cs_mesh_format (the names and
 * extensions are mesh_format.c's) */
static const char *const ASSIMP_IDS[] = {
    [CS_MESH_PLY] = "plyb",      /* binary PLY */
    [CS_MESH_OBJ] = "objnomtl",  /* OBJ without a .mtl file */
    [CS_MESH_GLB] = "glb2",      /* glTF 2.0 binary */
};
#define NFORMATS ((int)(sizeof ASSIMP_IDS / sizeof ASSIMP_IDS[0]))

/* --------------------------------------------------------------- writing */

static void set_ai_string(struct aiString *s, const char *text)
{
    size_t n = text ? strlen(text) : 0;
    if (n >= MAXLEN)
        n = MAXLEN - 1;
    if (n)
        memcpy(s->data, text, n);
    s->data[n] = '\0';
    s->length = (ai_uint32)n;
}

static void set_identity(struct aiMatrix4x4 *m)
{
    memset(m, 0, sizeof *m);
    m->a1 = m->b2 = m->c3 = m->d4 = 1;
}

static void free_mesh(struct aiMesh *mesh)
{
    if (!mesh)
        return;
    if (mesh->mFaces) {
        for (unsigned f = 0; f < mesh->mNumFaces; f++)
            free(mesh->mFaces[f].mIndices);
        free(mesh->mFaces);
    }
    free(mesh->mVertices);
    free(mesh->mNormals);
    free(mesh);
}

/* Frees a scene built by build_scene (and only such a scene). */
static void free_scene(struct aiScene *scene)
{
    if (!scene)
        return;
    if (scene->mMeshes) {
        for (unsigned m = 0; m < scene->mNumMeshes; m++)
            free_mesh(scene->mMeshes[m]);
        free(scene->mMeshes);
    }
    if (scene->mMaterials) {
        for (unsigned m = 0; m < scene->mNumMaterials; m++) {
            if (scene->mMaterials[m]) {
                free(scene->mMaterials[m]->mProperties);
                free(scene->mMaterials[m]);
            }
        }
        free(scene->mMaterials);
    }
    struct aiNode *root = scene->mRootNode;
    if (root) {
        if (root->mChildren) {
            for (unsigned c = 0; c < root->mNumChildren; c++) {
                if (root->mChildren[c])
                    free(root->mChildren[c]->mMeshes);
                free(root->mChildren[c]);
            }
            free(root->mChildren);
        }
        free(root);
    }
    free(scene);
}

/* Area-weighted vertex normals (renderers shade with them; without them the
 * OBJ exporter writes a made-up one). A vertex of no area gets +y. */
static void set_normals(const cs_mesh_view *view, struct aiVector3D *normals)
{
    double *n = calloc(3 * (size_t)view->nv, sizeof *n);
    if (n) {
        for (int t = 0; t < view->nt; t++) {
            const int *tri = &view->tri[3 * t];
            const double *a = &view->x[3 * tri[0]], *b = &view->x[3 * tri[1]],
                         *c = &view->x[3 * tri[2]];
            const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            const double cr[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                                  u[0] * w[1] - u[1] * w[0]};
            for (int k = 0; k < 3; k++)
                for (int d = 0; d < 3; d++)
                    n[3 * tri[k] + d] += cr[d];
        }
    }
    for (int i = 0; i < view->nv; i++) {
        double len = n ? sqrt(n[3 * i] * n[3 * i] + n[3 * i + 1] * n[3 * i + 1] +
                              n[3 * i + 2] * n[3 * i + 2])
                       : 0;
        if (len > 0 && isfinite(len)) {
            normals[i].x = (ai_real)(n[3 * i] / len);
            normals[i].y = (ai_real)(n[3 * i + 1] / len);
            normals[i].z = (ai_real)(n[3 * i + 2] / len);
        } else {
            normals[i].x = 0;
            normals[i].y = 1;
            normals[i].z = 0;
        }
    }
    free(n);
}

/* A mesh without triangles is points, a one-corner face per vertex: the
 * exporters write only what faces use (OBJ "p", glTF POINTS), and drop a
 * mesh without faces (PLY). */
static struct aiMesh *build_mesh(const cs_mesh_view *view, int index)
{
    struct aiMesh *mesh = calloc(1, sizeof *mesh);
    if (!mesh)
        return NULL;
    bool points = view->nt == 0;
    int nfaces = points ? view->nv : view->nt;
    mesh->mPrimitiveTypes = points ? aiPrimitiveType_POINT : aiPrimitiveType_TRIANGLE;
    mesh->mMaterialIndex = 0;
    if (view->name && *view->name) {
        set_ai_string(&mesh->mName, view->name);
    } else {
        char name[32];
        snprintf(name, sizeof name, "mesh_%d", index);
        set_ai_string(&mesh->mName, name);
    }
    mesh->mNumVertices = (unsigned)view->nv;
    mesh->mVertices = malloc((size_t)view->nv * sizeof *mesh->mVertices);
    mesh->mNormals = malloc((size_t)view->nv * sizeof *mesh->mNormals);
    mesh->mFaces = calloc((size_t)nfaces + 1, sizeof *mesh->mFaces);
    if (!mesh->mVertices || !mesh->mNormals || !mesh->mFaces) {
        free_mesh(mesh);
        return NULL;
    }
    mesh->mNumFaces = (unsigned)nfaces;
    for (int i = 0; i < view->nv; i++) {
        mesh->mVertices[i].x = (ai_real)view->x[3 * i + 0];
        mesh->mVertices[i].y = (ai_real)view->x[3 * i + 1];
        mesh->mVertices[i].z = (ai_real)view->x[3 * i + 2];
    }
    set_normals(view, mesh->mNormals);
    for (int t = 0; t < nfaces; t++) {
        struct aiFace *face = &mesh->mFaces[t];
        unsigned corners = points ? 1 : 3;
        face->mIndices = malloc(corners * sizeof *face->mIndices);
        if (!face->mIndices) {
            free_mesh(mesh);
            return NULL;
        }
        face->mNumIndices = corners;
        for (unsigned k = 0; k < corners; k++)
            face->mIndices[k] = points ? (unsigned)t : (unsigned)view->tri[3 * t + k];
    }
    return mesh;
}

/* An aiScene holding the views; NULL only when memory runs out. */
static struct aiScene *build_scene(int nmeshes, const cs_mesh_view *meshes)
{
    struct aiScene *scene = calloc(1, sizeof *scene);
    if (!scene)
        return NULL;
    /* mFlags stays 0: the exporters then treat the indexed meshes as they
     * are instead of expanding and re-joining them, which keeps the vertex
     * order of the file equal to the simulation's. */
    scene->mMeshes = calloc((size_t)nmeshes, sizeof *scene->mMeshes);
    scene->mMaterials = calloc(1, sizeof *scene->mMaterials);
    scene->mRootNode = calloc(1, sizeof *scene->mRootNode);
    if (!scene->mMeshes || !scene->mMaterials || !scene->mRootNode)
        goto fail;

    /* One material without properties: exporters look materials up by index. */
    scene->mMaterials[0] = calloc(1, sizeof *scene->mMaterials[0]);
    if (!scene->mMaterials[0])
        goto fail;
    scene->mNumMaterials = 1;

    for (int m = 0; m < nmeshes; m++) {
        scene->mMeshes[m] = build_mesh(&meshes[m], m);
        if (!scene->mMeshes[m])
            goto fail;
        scene->mNumMeshes = (unsigned)m + 1;
    }

    /* A child node per mesh, named like it: glTF would otherwise fold all
     * meshes of one node into a single mesh under the first name. */
    struct aiNode *root = scene->mRootNode;
    set_ai_string(&root->mName, "clothsim");
    set_identity(&root->mTransformation);
    root->mChildren = calloc((size_t)nmeshes, sizeof *root->mChildren);
    if (!root->mChildren)
        goto fail;
    root->mNumChildren = (unsigned)nmeshes;
    for (int m = 0; m < nmeshes; m++) {
        struct aiNode *child = calloc(1, sizeof *child);
        if (!child)
            goto fail;
        root->mChildren[m] = child;
        child->mParent = root;
        set_ai_string(&child->mName, scene->mMeshes[m]->mName.data);
        set_identity(&child->mTransformation);
        child->mMeshes = malloc(sizeof *child->mMeshes);
        if (!child->mMeshes)
            goto fail;
        child->mMeshes[0] = (unsigned)m;
        child->mNumMeshes = 1;
    }
    return scene;

fail:
    free_scene(scene);
    return NULL;
}

/* A frame of points only as a point-cloud PLY: vertices, no faces. Written
 * here because assimp's PLY exporter drops meshes without faces (its
 * enforced PreTransformVertices step) and would need one-corner faces. */
static bool ply_points(int nmeshes, const cs_mesh_view *meshes, cs_bytes *out)
{
    long nv = 0;
    for (int m = 0; m < nmeshes; m++)
        nv += meshes[m].nv;
    char header[256];
    int n = snprintf(header, sizeof header,
                     "ply\nformat binary_little_endian 1.0\ncomment clothsim point cloud\n"
                     "element vertex %ld\nproperty float x\nproperty float y\nproperty float z\n"
                     "end_header\n", nv);
    cs_bytes_put(out, header, (size_t)n);
    for (int m = 0; m < nmeshes; m++)
        for (int i = 0; i < 3 * meshes[m].nv; i++) {
            float f = (float)meshes[m].x[i];
            uint32_t bits;
            memcpy(&bits, &f, sizeof bits);
            unsigned char le[4] = {bits & 0xFF, (bits >> 8) & 0xFF, (bits >> 16) & 0xFF,
                                   bits >> 24};
            cs_bytes_put(out, le, sizeof le);
        }
    return !out->nomem;
}

/* Everything cs_mesh_write can check before assimp sees the data. */
static bool check_views(const char *path, int nmeshes, const cs_mesh_view *meshes,
                        char *err, size_t errlen)
{
    if (nmeshes <= 0 || !meshes) {
        set_err(err, errlen, "%s: no meshes to write", path);
        return false;
    }
    for (int m = 0; m < nmeshes; m++) {
        const cs_mesh_view *v = &meshes[m];
        const char *name = v->name ? v->name : "(unnamed)";
        if (v->nv <= 0 || v->nt < 0 || !v->x || (v->nt > 0 && !v->tri)) {
            set_err(err, errlen, "%s: mesh %d '%s' has no vertices", path, m, name);
            return false;
        }
        for (int i = 0; i < 3 * v->nt; i++) {
            if (v->tri[i] < 0 || v->tri[i] >= v->nv) {
                set_err(err, errlen, "%s: mesh %d '%s': triangle %d refers to vertex %d of %d",
                        path, m, name, i / 3, v->tri[i], v->nv);
                return false;
            }
        }
    }
    return true;
}

int cs_mesh_write(const char *path, cs_mesh_format format, int nmeshes,
                  const cs_mesh_view *meshes, char *err, size_t errlen)
{
    if (!path || !*path) {
        set_err(err, errlen, "cs_mesh_write: no file name given");
        return CS_ERR_BAD_INPUT;
    }
    if ((int)format < 0 || (int)format >= NFORMATS) {
        set_err(err, errlen, "%s: unknown mesh format %d", path, (int)format);
        return CS_ERR_BAD_INPUT;
    }
    if (!check_views(path, nmeshes, meshes, err, errlen))
        return CS_ERR_BAD_INPUT;

    bool points_only = format == CS_MESH_PLY;
    for (int m = 0; m < nmeshes; m++)
        points_only = points_only && meshes[m].nt == 0;
    cs_bytes points = {0};
    struct aiScene *scene = points_only ? NULL : build_scene(nmeshes, meshes);
    if (points_only ? !ply_points(nmeshes, meshes, &points) : !scene) {
        cs_bytes_free(&points);
        set_err(err, errlen, "%s: out of memory", path);
        return CS_ERR_NOMEM;
    }
    /* Assimp exports into memory and the bytes are written here, every
     * write checked: assimp's own file writer ignores a short fwrite and
     * fclose's result, so a full disk would give a truncated frame. */
    const struct aiExportDataBlob *blob =
        scene ? aiExportSceneToBlob(scene, ASSIMP_IDS[format], 0) : NULL;
    free_scene(scene);
    const void *data = blob ? blob->data : points.data;
    size_t size = blob ? blob->size : points.len;

    int status = CS_OK;
    if (!data || size == 0) {
        set_err(err, errlen, "cannot write %s: assimp's '%s' exporter failed",
                path, ASSIMP_IDS[format]);
        status = CS_ERR_BAD_INPUT;
    } else if (cs_file_write_atomic(path, data, size, err, errlen) != 0) {
        status = CS_ERR_BAD_INPUT;
    }
    if (blob)
        aiReleaseExportBlob(blob);
    cs_bytes_free(&points);
    return status;
}


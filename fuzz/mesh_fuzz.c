/* mesh_fuzz.c: libFuzzer target for the mesh import.
 *
 * The first byte of an input chooses the file's extension (low 3 bits:
 * ply obj stl glb gltf fbx dae off, which is what assimp goes by) and the
 * reader (next bits, mod 3: cs_mesh_import with the default placement,
 * cs_mesh_read, cs_mesh_catalog_read); the rest is the file, written into
 * build-fuzz/fuzz-root/assets/ beside copies of the small assets (so a
 * glTF finds its .bin and an OBJ its .mtl) and read through the public
 * function. fuzz/seed.sh gives each seed the byte of its format and of
 * cs_mesh_import.
 *
 * The readers run with CLOTHSIM_IMPORT_ISOLATION=0: the work that normally
 * happens in mesh_guard.c's child process (the pre-check of mesh_check.c,
 * assimp without post-processing, cs_mesh_check_scene, assimp's
 * triangulation, the walk, repairs and analysis of mesh_import.c and
 * mesh_repair.c) runs in this process, where libFuzzer sees its coverage
 * and the sanitizers see its faults. With the guard on, a child's coverage
 * never reaches libFuzzer and every crash becomes a clean error, so
 * nothing could be found. A crash here is therefore either a fault of ours
 * or one inside assimp that the guard contains in normal use: replay it
 * with CLOTHSIM_IMPORT_ISOLATION unset (tests/test_fuzz_regressions.c
 * does) to tell which. */
#include "import/import.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef CS_FUZZ_ROOT
#error "CS_FUZZ_ROOT must name build-fuzz/fuzz-root (fuzz/CMakeLists.txt defines it)"
#endif

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char *const extensions[8] = {"ply", "obj", "stl", "glb", "gltf", "fbx", "dae", "off"};

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    setenv("CLOTHSIM_IMPORT_ISOLATION", "0", 1);
    return 0;
}

static void check(int rc, bool have, const char *err)
{
    /* the contract of import.h: a result, or none with a message */
    if (rc == CS_OK && !have)
        abort();
    if (rc != CS_OK && (have || (rc == CS_ERR_BAD_INPUT && !err[0])))
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    unsigned sel = data[0];
    const char *ext = extensions[sel % 8];
    int reader = (int)((sel / 8) % 3);
    char path[1024];
    snprintf(path, sizeof path, "%s/assets/fuzz-input-%ld.%s", CS_FUZZ_ROOT, (long)getpid(), ext);
    FILE *f = fopen(path, "wb");
    if (!f) {
        fprintf(stderr, "mesh_fuzz: cannot write %s (run fuzz/seed.sh first)\n", path);
        abort();
    }
    if (size > 1)
        fwrite(data + 1, 1, size - 1, f);
    if (fclose(f) != 0)
        abort();

    char err[1024];
    err[0] = '\0';
    if (reader == 0) {
        cs_trimesh *mesh = NULL;
        cs_mesh_report report;
        int rc = cs_mesh_import(path, NULL, &mesh, &report, err, sizeof err);
        check(rc, mesh != NULL, err);
        if (mesh && (mesh->nv <= 0 || mesh->nt <= 0))
            abort();
        for (int i = 0; mesh && i < 3 * mesh->nt; i++)
            if (mesh->tri[i] < 0 || mesh->tri[i] >= mesh->nv)
                abort();
        cs_trimesh_destroy(mesh);
    } else if (reader == 1) {
        cs_trimesh *mesh = cs_mesh_read(path, err, sizeof err);
        check(mesh ? CS_OK : CS_ERR_BAD_INPUT, mesh != NULL, err);
        for (int i = 0; mesh && i < 3 * mesh->nt; i++)
            if (mesh->tri[i] < 0 || mesh->tri[i] >= mesh->nv)
                abort();
        cs_trimesh_destroy(mesh);
    } else {
        cs_mesh_catalog *cat = NULL;
        int rc = cs_mesh_catalog_read(path, &cat, err, sizeof err);
        check(rc, cat != NULL, err);
        cs_mesh_catalog_destroy(cat);
    }
    unlink(path);
    return 0;
}

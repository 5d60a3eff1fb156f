// levelset.cpp: the OpenVDB shim behind import/levelset.h, the only C++ in
// clothsim. Every entry point catches what OpenVDB throws and turns it into
// a sentence for the C side; nothing C++ crosses the interface.
#include "import/levelset.h"

#include "common/util.h"

#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>
#include <openvdb/tools/MeshToVolume.h>

#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <mutex>
#include <new>
#include <string>
#include <vector>

#include <unistd.h>

struct cs_levelset {
    openvdb::FloatGrid::Ptr grid;
    double voxel;
    double background;
    bool filled;
    // index = offset + world * inv_voxel when the transform is a plain
    // scale and shift (always, for grids made here): no virtual map call
    bool plain;
    double inv_voxel, offset[3];

    explicit cs_levelset(openvdb::FloatGrid::Ptr g)
        : grid(g), voxel(g->voxelSize()[0]),
          background(static_cast<double>(g->background())), filled(false), plain(false),
          inv_voxel(1.0 / voxel), offset{0, 0, 0}
    {
        const openvdb::math::Transform &t = g->transform();
        openvdb::Vec3d o = t.worldToIndex(openvdb::Vec3d(0, 0, 0));
        plain = true;
        for (int k = 0; k < 3; k++) {
            openvdb::Vec3d e(0, 0, 0);
            e[k] = 1;
            openvdb::Vec3d q = t.worldToIndex(e) - o;
            for (int j = 0; j < 3; j++)
                plain = plain && std::fabs(q[j] - (j == k ? inv_voxel : 0.0)) <= 1e-12 * inv_voxel;
            offset[k] = o[k];
        }
        openvdb::BoolMetadata::ConstPtr m =
            grid->getMetadata<openvdb::BoolMetadata>("clothsim_interior_filled");
        filled = m && m->value();
    }
};

namespace {

void set_err(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}

// Registers the grid types the file reader needs, once per process.
void init_once()
{
    static std::once_flag flag;
    std::call_once(flag, [] { openvdb::initialize(); });
}

}  // namespace

extern "C" {

const char *cs_levelset_library_version(void) { return OPENVDB_LIBRARY_VERSION_STRING; }

cs_levelset *cs_levelset_create(const cs_trimesh *mesh, double voxel_size, double band_voxels,
                                bool fill_interior, char *err, size_t errlen)
{
    if (!mesh || mesh->nt < 1 || mesh->nv < 3) {
        set_err(err, errlen, "the mesh has no triangles");
        return nullptr;
    }
    if (!(voxel_size > 0) || !std::isfinite(voxel_size) || !(band_voxels >= 1)) {
        set_err(err, errlen, "voxel size must be > 0 and the band at least 1 voxel");
        return nullptr;
    }
    try {
        init_once();
        std::vector<openvdb::Vec3s> points((size_t)mesh->nv);
        std::vector<openvdb::Vec3I> triangles((size_t)mesh->nt);
        std::vector<openvdb::Vec4I> quads;
        for (int i = 0; i < mesh->nv; i++)
            points[(size_t)i] = openvdb::Vec3s((float)mesh->x[3 * i], (float)mesh->x[3 * i + 1],
                                               (float)mesh->x[3 * i + 2]);
        for (int t = 0; t < mesh->nt; t++)
            triangles[(size_t)t] = openvdb::Vec3I((openvdb::Index32)mesh->tri[3 * t],
                                                  (openvdb::Index32)mesh->tri[3 * t + 1],
                                                  (openvdb::Index32)mesh->tri[3 * t + 2]);
        openvdb::math::Transform::Ptr xform =
            openvdb::math::Transform::createLinearTransform(voxel_size);
        // A filled interior gives every point inside a true distance and a
        // normal, however deep a fast particle or a moving body pushed it.
        float inside = fill_interior ? std::numeric_limits<float>::max() : (float)band_voxels;
        openvdb::FloatGrid::Ptr grid = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
            *xform, points, triangles, quads, (float)band_voxels, inside);
        if (!grid || grid->activeVoxelCount() == 0) {
            set_err(err, errlen, "OpenVDB produced an empty grid (is the voxel size far larger "
                                 "than the mesh?)");
            return nullptr;
        }
        grid->setGridClass(openvdb::GRID_LEVEL_SET);
        grid->insertMeta("clothsim_interior_filled", openvdb::BoolMetadata(fill_interior));
        return new cs_levelset(grid);
    } catch (const std::bad_alloc &) {
        set_err(err, errlen, "out of memory converting the mesh to a level set");
    } catch (const std::exception &e) {
        set_err(err, errlen, "OpenVDB failed: %s", e.what());
    }
    return nullptr;
}

void cs_levelset_destroy(cs_levelset *ls) { delete ls; }

namespace {
struct vdb_file {
    const cs_levelset *ls;
    const char *grid_name;
    int nmeta;
    const char *const *keys, *const *values;
};
} // namespace

// The grid as the VDB file tmp; no exception leaves (cs_write_atomic is C).
static int fill_vdb(const char *tmp, void *ctx, char *why, size_t whylen)
{
    const vdb_file *v = static_cast<const vdb_file *>(ctx);
    try {
        init_once();
        // The file gets a copy that shares the tree, so names and metadata
        // added here do not touch the grid in use.
        openvdb::FloatGrid::Ptr copy = v->ls->grid->copy();
        copy->setName(v->grid_name && *v->grid_name ? v->grid_name : "phi");
        for (int i = 0; i < v->nmeta; i++)
            copy->insertMeta(v->keys[i], openvdb::StringMetadata(v->values[i]));
        openvdb::GridPtrVec grids;
        grids.push_back(copy);
        openvdb::io::File file(tmp);
        file.write(grids);
        file.close();
    } catch (const std::exception &e) {
        std::snprintf(why, whylen, "%s", e.what());
        return -1;
    }
    return 0;
}

int cs_levelset_write(const cs_levelset *ls, const char *path, const char *grid_name, int nmeta,
                      const char *const *keys, const char *const *values, char *err,
                      size_t errlen)
{
    vdb_file v = {ls, grid_name, nmeta, keys, values};
    // a temporary name of this process's own: two runs may fill the same
    // cache entry
    return cs_write_atomic(path, true, fill_vdb, &v, err, errlen);
}

cs_levelset *cs_levelset_read(const char *path, const char *meta_key, const char *meta_value,
                              char *err, size_t errlen)
{
    try {
        init_once();
        openvdb::io::File file(path);
        file.open();
        openvdb::GridPtrVecPtr grids = file.getGrids();
        file.close();
        for (openvdb::GridBase::Ptr base : *grids) {
            openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
            if (!grid)
                continue;
            if (meta_key) {
                openvdb::StringMetadata::ConstPtr m =
                    grid->getMetadata<openvdb::StringMetadata>(meta_key);
                if (!m || m->value() != (meta_value ? meta_value : "")) {
                    set_err(err, errlen, "%s was made from other input (%s differs)", path,
                            meta_key);
                    return nullptr;
                }
            }
            const openvdb::Vec3d vs = grid->voxelSize();
            if (!grid->transform().isLinear() || !grid->hasUniformVoxels() || !(vs[0] > 0)) {
                set_err(err, errlen, "%s: the grid's transform is not a uniform scale", path);
                return nullptr;
            }
            return new cs_levelset(grid);
        }
        set_err(err, errlen, "%s holds no float grid", path);
    } catch (const std::bad_alloc &) {
        set_err(err, errlen, "out of memory reading %s", path);
    } catch (const std::exception &e) {
        set_err(err, errlen, "cannot read %s: %s", path, e.what());
    }
    return nullptr;
}

void cs_levelset_get_info(const cs_levelset *ls, cs_levelset_info *info)
{
    std::memset(info, 0, sizeof *info);
    info->voxel_size = ls->voxel;
    info->exterior_band = ls->background;
    info->interior_filled = ls->filled;
    info->active_voxels = (long long)ls->grid->activeVoxelCount();
    info->leaf_nodes = (long long)ls->grid->tree().leafCount();
    info->memory_bytes = (size_t)ls->grid->memUsage();
    openvdb::CoordBBox box = ls->grid->evalActiveVoxelBoundingBox();
    for (int k = 0; k < 3; k++) {
        openvdb::Vec3d lo = ls->grid->indexToWorld(box.min().asVec3d());
        openvdb::Vec3d hi = ls->grid->indexToWorld(box.max().asVec3d());
        info->min[k] = lo[k] - ls->voxel;
        info->max[k] = hi[k] + ls->voxel;
        info->dim[k] = box.max()[k] - box.min()[k] + 1;
    }
}

double cs_levelset_phi(const void *data, const double p[3], double grad[3])
{
    const cs_levelset *ls = static_cast<const cs_levelset *>(data);
    // An accessor of this query's own caches the path to the last leaf,
    // which makes its 64 lookups cheap; one per query (unregistered, so
    // cheap to make) keeps queries thread-safe: threads share the bodies.
    openvdb::FloatGrid::ConstUnsafeAccessor acc = ls->grid->getConstUnsafeAccessor();
    openvdb::Vec3d q;
    if (ls->plain)
        for (int k = 0; k < 3; k++)
            q[k] = ls->offset[k] + p[k] * ls->inv_voxel;
    else
        q = ls->grid->worldToIndex(openvdb::Vec3d(p[0], p[1], p[2]));
    int base[3];
    double f[3];
    for (int k = 0; k < 3; k++) {
        double fl = std::floor(q[k]);
        // Far outside the index range: the background, which is what the
        // grid reads there anyway.
        if (!(std::fabs(fl) < 1e9)) {
            grad[0] = grad[2] = 0;
            grad[1] = 1;
            return ls->background;
        }
        base[k] = (int)fl;
        f[k] = q[k] - fl;
    }
    // v[a][b][c] at voxel base + (a-1, b-1, c-1): the cell's 8 corners and
    // the 24 neighbours their central differences need (32 of the 64).
    double v[4][4][4];
    using LeafT = openvdb::FloatGrid::TreeType::LeafNodeType;
    const LeafT *leaf = nullptr;
    bool one_leaf = true;
    for (int k = 0; k < 3; k++)
        one_leaf = one_leaf && ((base[k] - 1) & ~7) == ((base[k] + 2) & ~7);
    const float *buf = nullptr;
    if (one_leaf) { // read the leaf's buffer, no tree walk per value
        leaf = acc.probeConstLeaf(openvdb::Coord(base[0] - 1, base[1] - 1, base[2] - 1));
        buf = leaf ? leaf->buffer().data() : nullptr;
    }
    for (int a = 0; a < 4; a++)
        for (int b = 0; b < 4; b++)
            for (int d = 0; d < 4; d++) {
                int outer = (a == 0 || a == 3) + (b == 0 || b == 3) + (d == 0 || d == 3);
                if (outer > 1)
                    continue;
                int x = base[0] + a - 1, y = base[1] + b - 1, z = base[2] + d - 1;
                v[a][b][d] = buf ? (double)buf[((x & 7) << 6) | ((y & 7) << 3) | (z & 7)]
                                 : (double)acc.getValue(openvdb::Coord(x, y, z));
            }
    double phi = 0, g[3] = {0, 0, 0};
    for (int a = 1; a <= 2; a++)
        for (int b = 1; b <= 2; b++)
            for (int d = 1; d <= 2; d++) {
                double w = (a == 2 ? f[0] : 1 - f[0]) * (b == 2 ? f[1] : 1 - f[1]) *
                           (d == 2 ? f[2] : 1 - f[2]);
                phi += w * v[a][b][d];
                g[0] += w * (v[a + 1][b][d] - v[a - 1][b][d]);
                g[1] += w * (v[a][b + 1][d] - v[a][b - 1][d]);
                g[2] += w * (v[a][b][d + 1] - v[a][b][d - 1]);
            }
    double len = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (len > 0) {
        for (int k = 0; k < 3; k++)
            grad[k] = g[k] / len;
    } else {  // flat (clamped band or a medial point): any direction will do
        grad[0] = grad[2] = 0;
        grad[1] = 1;
    }
    return phi;
}

}  // extern "C"

/* levelset.h: signed distance grids of triangle meshes (OpenVDB).
 *
 * The one C++ file of clothsim, levelset.cpp, implements this C interface,
 * so the rest of the project stays C11. A grid lives in the frame the mesh
 * was given in (a body's local frame); cs_levelset_phi has the signature of
 * cs_body_phi_fn, so a grid plugs straight into cs_body_def.phi_fn.
 *
 * Sign: OpenVDB's meshToVolume decides inside and outside by sweeping from
 * the grid's boundary along each axis and flood filling the voxels that can
 * be reached without crossing the surface; voxels the surface cuts take the
 * sign from the orientation of their closest triangle. A closed mesh gets a
 * correct sign; through a hole wider than about a voxel the outside leaks in.
 * The importer closes holes before conversion (cs_mesh_close_holes).
 */
#ifndef CS_LEVELSET_H
#define CS_LEVELSET_H

#include <stdbool.h>
#include <stddef.h>

#include "sim/sim.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct cs_levelset cs_levelset;

typedef struct cs_levelset_info {
    double voxel_size;        /* m */
    double exterior_band;     /* m; beyond it phi reads +exterior_band */
    bool interior_filled;     /* every inside voxel holds its distance */
    long long active_voxels;
    long long leaf_nodes;
    size_t memory_bytes;      /* of the grid in memory */
    double min[3], max[3];    /* bounds of the active voxels, one voxel added */
    int dim[3];               /* voxels along each axis of those bounds */
} cs_levelset_info;

/* Converts a triangle mesh to a signed distance grid of voxel_size with an
 * exterior band of band_voxels voxels. fill_interior: every voxel inside
 * holds its distance (else the interior band is band_voxels wide too and
 * deeper points read -band). NULL with a sentence in err on failure. */
cs_levelset *cs_levelset_create(const cs_trimesh *mesh, double voxel_size, double band_voxels,
                                bool fill_interior, char *err, size_t errlen);
void cs_levelset_destroy(cs_levelset *ls);

/* Writes the grid as a .vdb file, atomically (a temporary file beside it,
 * then renamed), with string metadata pairs on the grid, e.g.
 * {"clothsim_key", hash}. */
int cs_levelset_write(const cs_levelset *ls, const char *path, const char *grid_name, int nmeta,
                      const char *const *keys, const char *const *values, char *err,
                      size_t errlen);

/* Reads the first float grid of a .vdb file. With meta_key given, the grid
 * must carry that metadata with exactly meta_value (else NULL, a stale or
 * foreign file). */
cs_levelset *cs_levelset_read(const char *path, const char *meta_key, const char *meta_value,
                              char *err, size_t errlen);

void cs_levelset_get_info(const cs_levelset *ls, cs_levelset_info *info);

/* Trilinearly interpolated phi at p (in the grid's frame) and the unit
 * gradient, interpolated the same way from central differences at the
 * voxels; a cs_body_phi_fn for data = the cs_levelset. Thread-safe (the
 * simulation's threads query bodies side by side): each query makes its
 * own accessor. */
double cs_levelset_phi(const void *ls, const double p[3], double grad[3]);

/* Makes the grid body's distance: phi from ls, bounded by the grid's
 * box (the body's shape and motion are the caller's). */
static inline void cs_levelset_attach(cs_body_def *body, cs_levelset *ls)
{
    cs_levelset_info info;
    cs_levelset_get_info(ls, &info);
    body->phi_fn = cs_levelset_phi;
    body->phi_data = ls;
    body->phi_bounded = true;
    for (int k = 0; k < 3; k++) {
        body->phi_min[k] = info.min[k];
        body->phi_max[k] = info.max[k];
    }
}

/* The library version, part of the cache key ("10.0.1"). */
const char *cs_levelset_library_version(void);

#ifdef __cplusplus
}
#endif
#endif

/* body_bounds.c: world boxes of bodies, for the partition of body
 * occupancy (body_grid.c). A box must hold every point where the body's
 * phi < offset (where it collides); planes, and distance functions without
 * a box, are unbounded. */
#include "sim/body_grid.h"
#include "sim/vec3.h"

bool cs_body_def_bounds(const cs_body_def *b, double t, double lo[3], double hi[3])
{
    double lmin[3], lmax[3];
    if (b->phi_fn) { /* phi_fn replaces the shape, as in cs_body_def_phi */
        if (!b->phi_bounded)
            return false;
        for (int k = 0; k < 3; k++) {
            lmin[k] = b->phi_min[k];
            lmax[k] = b->phi_max[k];
        }
    } else {
        switch (b->shape) {
        case CS_BODY_SPHERE:
            for (int k = 0; k < 3; k++)
                lmin[k] = -b->radius, lmax[k] = b->radius;
            break;
        case CS_BODY_BOX:
            for (int k = 0; k < 3; k++)
                lmin[k] = -b->half_extents[k], lmax[k] = b->half_extents[k];
            break;
        case CS_BODY_CYLINDER:
            lmin[0] = lmin[2] = -b->radius;
            lmax[0] = lmax[2] = b->radius;
            lmin[1] = -b->half_height;
            lmax[1] = b->half_height;
            break;
        default:
            return false;
        }
    }
    double R[9], c[3], mid[3], half[3], wmid[3];
    cs_motion_pose(&b->motion, t, R, c, NULL, NULL);
    for (int k = 0; k < 3; k++) {
        mid[k] = 0.5 * (lmin[k] + lmax[k]);
        half[k] = 0.5 * (lmax[k] - lmin[k]);
    }
    cs_mat_apply(R, mid, wmid);
    bool sphere = !b->phi_fn && b->shape == CS_BODY_SPHERE;
    for (int i = 0; i < 3; i++) {
        /* the rotated box's extent along world axis i; a sphere's is r */
        double h = sphere ? half[i]
                          : fabs(R[3 * i]) * half[0] + fabs(R[3 * i + 1]) * half[1] +
                                fabs(R[3 * i + 2]) * half[2];
        double centre = c[i] + wmid[i];
        /* round-off of the pose and of phi must not push a point that phi
         * calls inside out of the box */
        double pad = 1e-9 * (fabs(centre) + h) + 1e-12 + b->offset;
        lo[i] = centre - h - pad;
        hi[i] = centre + h + pad;
    }
    return true;
}

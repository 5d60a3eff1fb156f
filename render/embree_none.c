/* embree_none.c: the ray-traced engine in a build without Embree
 * (-DCLOTHSIM_WITH_EMBREE=OFF), in place of embree.c: a renderer asked for
 * it is refused with this sentence, and the preview engine is unchanged. */
#include "render/internal.h"

#include "common/error.h"

#define NO_EMBREE \
    CS_MISSING_PART("Embree", "the ray-traced engine needs it", "CLOTHSIM_WITH_EMBREE")

cs_embree *cs_embree_create(const cs_render_settings *settings, char *err, size_t errlen)
{
    (void)settings;
    cs_render_error(err, errlen, "%s", NO_EMBREE);
    return NULL;
}

/* No engine is ever made here: nothing to free or draw with. */
void cs_embree_destroy(cs_embree *engine) { (void)engine; }

int cs_embree_draw(cs_embree *engine, const cs_prepared_scene *scene,
                   const cs_render_camera *camera, cs_image *image, cs_render_stats *stats,
                   char *err, size_t errlen)
{
    (void)engine, (void)scene, (void)camera, (void)image, (void)stats;
    cs_render_error(err, errlen, "%s", NO_EMBREE);
    return CS_ERR_FAILED;
}

/* preview_none.c: the preview engine in a build without OSMesa
 * (-DCLOTHSIM_WITH_OSMESA=OFF), in place of preview.c: a renderer asked
 * for it is refused with this sentence, and the ray-traced engine is
 * unchanged. */
#include "render/internal.h"

#include "common/error.h"

#define NO_OSMESA \
    CS_MISSING_PART("OSMesa", "the preview engine needs it", "CLOTHSIM_WITH_OSMESA")

cs_preview *cs_preview_create(const cs_render_settings *settings, char *err, size_t errlen)
{
    (void)settings;
    cs_render_error(err, errlen, "%s", NO_OSMESA);
    return NULL;
}

/* No engine is ever made here: nothing to free or draw with. */
void cs_preview_destroy(cs_preview *engine) { (void)engine; }

int cs_preview_draw(cs_preview *engine, const cs_prepared_scene *scene,
                    const cs_render_camera *camera, cs_image *image, cs_render_stats *stats,
                    char *err, size_t errlen)
{
    (void)engine, (void)scene, (void)camera, (void)image, (void)stats;
    cs_render_error(err, errlen, "%s", NO_OSMESA);
    return CS_ERR_FAILED;
}

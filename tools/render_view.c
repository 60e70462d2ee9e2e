// The PNG of drift render: tone-mapped (--tonemap), or through an OpenColorIO view transform
// (--view, --display, --look, --ocio-config; docs/colour.md).
#include "cli.h"
#include "drift/image_io.h"
#include "render.h"

#include <stdio.h>

drift_result render_save_png(drift_context *ctx, const render_options *o, const char *path,
                             const drift_image *image)
{
    drift_tonemap_params tonemap = render_png_tonemap(o, image);
    if (!o->view) {
        return drift_image_save_png(ctx, path, image, &tonemap);
    }
    drift_ocio_view view = { .config = o->ocio_config,
                             .display = o->display,
                             .view = o->view,
                             .look = o->look,
                             .exposure_stops = tonemap.exposure_stops };
    return drift_image_save_png_view(ctx, path, image, &view);
}

bool render_check_view(const render_options *o)
{
    if ((o->display || o->look || o->ocio_config) && !o->view) {
        fprintf(stderr, "drift render: --display, --look and --ocio-config need --view NAME\n");
        return false;
    }
    if (!o->view) {
        return true;
    }
    if (!drift_ocio_available()) {
        fprintf(stderr, "drift render: --view needs OpenColorIO; this drift was built without "
                        "it (install libopencolorio-dev and rebuild)\n");
        return false;
    }
    // The names now, not after a render that could then not be written.
    drift_ocio_view view = {
        .config = o->ocio_config, .display = o->display, .view = o->view, .look = o->look
    };
    drift_context *ctx = NULL;
    drift_result r = drift_context_create(
        &(drift_context_desc){ .thread_count = 1, .logger = cli_stderr_logger(false) }, &ctx);
    r = r == DRIFT_OK ? drift_ocio_check_view(ctx, "--view", &view) : r;
    drift_context_destroy(ctx);
    return r == DRIFT_OK;
}

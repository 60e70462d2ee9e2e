// Private: the OpenColorIO shim (image_ocio.cpp), compiled where the build found OpenColorIO
// (DRIFT_HAVE_OCIO); image_io.c calls it for drift_image_save_png_view.
#ifndef DRIFT_IMAGE_OCIO_H
#define DRIFT_IMAGE_OCIO_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

// Applies the config's display/view transform (from its scene_linear role) to `count` packed
// RGB floats in place; look may be NULL or "" (none), display NULL or "" (the config's
// default); count 0 checks the names only. Returns 0, or non-zero with a message in why[why_size]
// (no exception escapes).
int drift__ocio_apply(const char *config, const char *display, const char *view, const char *look,
                      float *rgb, size_t count, char *why, size_t why_size);

#ifdef __cplusplus
}
#endif

#endif

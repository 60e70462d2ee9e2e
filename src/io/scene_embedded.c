// Textures held inside the scene file: a .glb's images (bufferViews) and glTF data URIs, which
// assimp 5.2 hands over as embedded aiTextures named "*N" (or by the image's file name).
// Compressed ones (PNG, JPEG, ...) are decoded from memory by drift_image_load_memory, as a
// file beside the scene would be; raw ones (mHeight > 0) are 8-bit sRGB BGRA texels.
#include "drift/image_io.h"
#include "scene_io_internal.h"

#include <assimp/scene.h>
#include <assimp/texture.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// The assimp texture `ref` names ("*3", or a file name an embedded texture carries), or -1.
static int embedded_index(const struct aiScene *ai, const char *ref)
{
    if (ref[0] == '*') {
        char *end = NULL;
        long i = strtol(ref + 1, &end, 10);
        return end != ref + 1 && *end == '\0' && i >= 0 && i < (long)ai->mNumTextures ? (int)i : -1;
    }
    for (unsigned i = 0; i < ai->mNumTextures; ++i) {
        const struct aiTexture *t = ai->mTextures[i];
        if (t && t->mFilename.length > 0 && strcmp(t->mFilename.data, ref) == 0) {
            return (int)i;
        }
    }
    return -1;
}

// An uncompressed aiTexture (BGRA8, sRGB) as a linear RGB image.
static drift_result raw_texels(drift_context *ctx, const struct aiTexture *t, drift_image *out)
{
    if (t->mWidth > DRIFT_IMAGE_MAX_DIMENSION || t->mHeight > DRIFT_IMAGE_MAX_DIMENSION) {
        return DRIFT_ERR_UNSUPPORTED;
    }
    drift_result r = drift_image_create(ctx, (int32_t)t->mWidth, (int32_t)t->mHeight, 3, out);
    for (uint32_t y = 0; r == DRIFT_OK && y < t->mHeight; ++y) {
        for (uint32_t x = 0; x < t->mWidth; ++x) {
            const struct aiTexel *texel = &t->pcData[(size_t)y * t->mWidth + x];
            float *p = drift_image_pixel(out, (int32_t)x, (int32_t)y);
            p[0] = drift_srgb_to_linear((float)texel->r / 255.0f);
            p[1] = drift_srgb_to_linear((float)texel->g / 255.0f);
            p[2] = drift_srgb_to_linear((float)texel->b / 255.0f);
        }
    }
    return r;
}

bool drift__is_embedded_texture(const struct aiScene *ai, const char *ref)
{
    return ref[0] == '*' || embedded_index(ai, ref) >= 0;
}

drift_result drift__embedded_texture(drift_scene *scene, const struct aiScene *ai, const char *ref,
                                     uint32_t *loaded, const char *where, int line,
                                     uint32_t *out_index)
{
    drift_context *ctx = scene->ctx;
    int i = embedded_index(ai, ref);
    if (i < 0) {
        drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_PARSE, where, line,
                  "embedded texture '%s' is not in the file", ref);
        return DRIFT_ERR_PARSE;
    }
    if (loaded[i] != DRIFT_INVALID_INDEX) {
        *out_index = loaded[i];
        return DRIFT_OK;
    }
    const struct aiTexture *t = ai->mTextures[i];
    char name[DRIFT__PATH_MAX];
    snprintf(name, sizeof name, "%s (embedded texture %d%s%s)", where ? where : "scene", i,
             t->mFilename.length ? ": " : "", t->mFilename.length ? t->mFilename.data : "");
    drift_image image = { 0 };
    drift_result r = t->mHeight == 0
                         ? drift_image_load_memory(ctx, name, t->pcData, t->mWidth, &image)
                         : raw_texels(ctx, t, &image);
    if (r != DRIFT_OK) {
        drift_image_destroy(ctx, &image);
        drift_log(ctx, DRIFT_LOG_WARNING, r, where, line, "cannot decode %s", name);
        return r;
    }
    r = drift_scene_add_texture(scene, image, out_index); // owns the pixels, even on failure
    if (r == DRIFT_OK) {
        loaded[i] = *out_index;
    }
    return r;
}

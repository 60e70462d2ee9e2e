// OpenEXR back end on the OpenEXRCore C API (libopenexr 3.1).
//
// Reading decodes from a buffer already in memory through a custom read function, so file
// errors (DRIFT_ERR_IO) are told apart from corrupt content (DRIFT_ERR_PARSE) and the fuzzer
// exercises exactly the code the loader runs. Writing goes through a custom write function
// into the temp file of drift__image_temp, which is renamed over the target on success.
//
// DWAA/DWAB parts go to image_exr_dwa.cpp (OpenEXRCore 3.1 has no DWA decoder); the part and
// channel choice and every limit below stay here, so both codecs follow the same rules.
//
// OpenEXRCore prints to stderr unless an error handler is installed; ours keeps the last
// message so the one error we log can carry it (the library never prints).
#include "image_exr_dwa.h"
#include "image_io_internal.h"

#include <OpenEXR/openexr.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>

typedef struct exr_stream {
    drift_context *ctx;
    const char *path;
    const uint8_t *data; // reading
    size_t size;
    drift__image_temp *temp; // writing
    char message[256];       // last OpenEXRCore error text
} exr_stream;

// The stream of the load or save running on this thread. The error handler must not ask the
// context for its user data: OpenEXRCore calls the handler with a write context's mutex held
// and exr_get_user_data takes that mutex again, so a failed write (a full disk) deadlocked.
static _Thread_local exr_stream *exr_active;

static void exr_error_handler(exr_const_context_t f, exr_result_t code, const char *msg)
{
    (void)f;
    exr_stream *s = exr_active;
    if (s) {
        snprintf(s->message, sizeof(s->message), "%s",
                 msg ? msg : exr_get_error_code_as_string(code));
    }
}

static int64_t exr_read_memory(exr_const_context_t f, void *user, void *buffer, uint64_t size,
                               uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    const exr_stream *s = user;
    (void)f;
    (void)error_cb;
    if (offset >= s->size) {
        return 0;
    }
    uint64_t n = s->size - offset < size ? s->size - offset : size;
    memcpy(buffer, s->data + offset, (size_t)n);
    return (int64_t)n;
}

static int64_t exr_size_memory(exr_const_context_t f, void *user)
{
    (void)f;
    return (int64_t)((const exr_stream *)user)->size;
}

static int64_t exr_write_temp(exr_const_context_t f, void *user, const void *buffer, uint64_t size,
                              uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    exr_stream *s = user;
    if (!drift__image_temp_write(s->temp, buffer, (size_t)size, offset)) {
        char why[160];
        error_cb(f, EXR_ERR_WRITE_IO, "write of %llu bytes failed: %s", (unsigned long long)size,
                 drift__write_errno_text(errno, why, sizeof(why)));
        return -1;
    }
    return (int64_t)size;
}

static drift_result exr_fail(exr_stream *s, exr_result_t rv, const char *what)
{
    drift_result code = rv == EXR_ERR_OUT_OF_MEMORY             ? DRIFT_ERR_OUT_OF_MEMORY
                        : rv == EXR_ERR_FEATURE_NOT_IMPLEMENTED ? DRIFT_ERR_UNSUPPORTED
                        : s->temp                               ? DRIFT_ERR_IO
                                                                : DRIFT_ERR_PARSE;
    drift_log(s->ctx, DRIFT_LOG_ERROR, code, s->path, 0, "%s: %s%s%s", what,
              exr_get_error_code_as_string(rv), s->message[0] ? ": " : "", s->message);
    return code;
}

// --- LOADING ---

// Which file channel feeds each of R, G, B (-1: none). `grey` when one channel feeds all three.
typedef struct channel_pick {
    int index[3];
    bool grey;
} channel_pick;

static int find_channel(const exr_attr_chlist_t *list, const char *name, size_t prefix_len,
                        const char *prefix)
{
    for (int i = 0; i < list->num_channels; ++i) {
        const char *n = list->entries[i].name.str;
        if (!n) {
            continue;
        }
        if (prefix_len > 0) {
            if (strncmp(n, prefix, prefix_len) != 0 || n[prefix_len] != '.') {
                continue;
            }
            n += prefix_len + 1;
        }
        if (strcmp(n, name) == 0) {
            return i;
        }
    }
    return -1;
}

// Default layer R,G,B, then default Y, then the first layer (alphabetic) with .R,.G,.B.
static bool pick_channels(const exr_attr_chlist_t *list, channel_pick *out)
{
    *out = (channel_pick){ { -1, -1, -1 }, false };
    const char *rgb[3] = { "R", "G", "B" };
    for (int c = 0; c < 3; ++c) {
        out->index[c] = find_channel(list, rgb[c], 0, NULL);
    }
    if (out->index[0] >= 0 && out->index[1] >= 0 && out->index[2] >= 0) {
        return true;
    }
    int y = find_channel(list, "Y", 0, NULL);
    if (y >= 0) {
        *out = (channel_pick){ { y, -1, -1 }, true };
        return true;
    }
    for (int i = 0; i < list->num_channels; ++i) {
        const char *n = list->entries[i].name.str;
        const char *dot = n ? strrchr(n, '.') : NULL;
        if (!dot || strcmp(dot, ".R") != 0) {
            continue;
        }
        size_t prefix_len = (size_t)(dot - n);
        for (int c = 0; c < 3; ++c) {
            out->index[c] = find_channel(list, rgb[c], prefix_len, n);
        }
        if (out->index[0] >= 0 && out->index[1] >= 0 && out->index[2] >= 0) {
            return true;
        }
    }
    *out = (channel_pick){ { -1, -1, -1 }, false };
    return false;
}

// Decodes one chunk whose top-left pixel is (px, py) in image coordinates.
static exr_result_t decode_chunk(exr_context_t f, int part, const exr_chunk_info_t *cinfo,
                                 exr_decode_pipeline_t *decoder, const channel_pick *pick,
                                 drift_image *img, int64_t px, int64_t py)
{
    if (px < 0 || py < 0 || cinfo->width <= 0 || cinfo->height <= 0 ||
        px + cinfo->width > img->width || py + cinfo->height > img->height) {
        return EXR_ERR_CORRUPT_CHUNK;
    }
    bool first = decoder->channels == NULL;
    exr_result_t rv = first ? exr_decoding_initialize(f, part, cinfo, decoder)
                            : exr_decoding_update(f, part, cinfo, decoder);
    if (rv != EXR_ERR_SUCCESS) {
        return rv;
    }
    const exr_attr_chlist_t *list = NULL;
    rv = exr_get_channels(f, part, &list);
    if (rv != EXR_ERR_SUCCESS) {
        return rv;
    }
    float *base = drift_image_pixel(img, (int32_t)px, (int32_t)py);
    for (int c = 0; c < decoder->channel_count; ++c) {
        exr_coding_channel_info_t *ch = &decoder->channels[c];
        ch->decode_to_ptr = NULL; // skipped by the unpacker
        for (int k = 0; k < 3; ++k) {
            if (pick->index[k] >= 0 &&
                strcmp(ch->channel_name, list->entries[pick->index[k]].name.str) == 0) {
                if (ch->width != cinfo->width || ch->height != cinfo->height) {
                    return EXR_ERR_CORRUPT_CHUNK;
                }
                ch->decode_to_ptr = (uint8_t *)(base + k);
                ch->user_data_type = EXR_PIXEL_FLOAT;
                ch->user_bytes_per_element = (int16_t)sizeof(float);
                ch->user_pixel_stride = (int32_t)(sizeof(float) * 3);
                ch->user_line_stride = (int32_t)(sizeof(float) * (size_t)img->stride);
            }
        }
    }
    if (first) {
        rv = exr_decoding_choose_default_routines(f, part, decoder);
        if (rv != EXR_ERR_SUCCESS) {
            return rv;
        }
    }
    return exr_decoding_run(f, part, decoder);
}

static exr_result_t decode_part(exr_context_t f, int part, exr_storage_t storage,
                                const exr_attr_box2i_t *dw, const channel_pick *pick,
                                drift_image *img)
{
    exr_decode_pipeline_t decoder = EXR_DECODE_PIPELINE_INITIALIZER;
    exr_result_t rv = EXR_ERR_SUCCESS;
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lines = 0;
        rv = exr_get_scanlines_per_chunk(f, part, &lines);
        if (rv == EXR_ERR_SUCCESS && lines <= 0) {
            rv = EXR_ERR_INVALID_ATTR;
        }
        for (int64_t y = 0; rv == EXR_ERR_SUCCESS && y < img->height; y += lines) {
            exr_chunk_info_t cinfo = { 0 };
            rv = exr_read_scanline_chunk_info(f, part, (int)(dw->min.y + y), &cinfo);
            if (rv == EXR_ERR_SUCCESS) {
                rv = decode_chunk(f, part, &cinfo, &decoder, pick, img,
                                  (int64_t)cinfo.start_x - dw->min.x,
                                  (int64_t)cinfo.start_y - dw->min.y);
            }
        }
    } else {
        int32_t tile_w = 0, tile_h = 0, level_w = 0, level_h = 0;
        rv = exr_get_tile_sizes(f, part, 0, 0, &tile_w, &tile_h);
        if (rv == EXR_ERR_SUCCESS) {
            rv = exr_get_level_sizes(f, part, 0, 0, &level_w, &level_h);
        }
        if (rv == EXR_ERR_SUCCESS &&
            (tile_w <= 0 || tile_h <= 0 || level_w != img->width || level_h != img->height)) {
            rv = EXR_ERR_INVALID_ATTR;
        }
        for (int64_t ty = 0; rv == EXR_ERR_SUCCESS && ty * tile_h < img->height; ++ty) {
            for (int64_t tx = 0; rv == EXR_ERR_SUCCESS && tx * tile_w < img->width; ++tx) {
                exr_chunk_info_t cinfo = { 0 };
                rv = exr_read_tile_chunk_info(f, part, (int)tx, (int)ty, 0, 0, &cinfo);
                if (rv == EXR_ERR_SUCCESS) {
                    rv = decode_chunk(f, part, &cinfo, &decoder, pick, img, tx * tile_w,
                                      ty * tile_h);
                }
            }
        }
    }
    exr_result_t drv = exr_decoding_destroy(f, &decoder);
    return rv != EXR_ERR_SUCCESS ? rv : drv;
}

static drift_result exr_load(drift_context *ctx, const char *path, const uint8_t *data, size_t size,
                             drift_image *out_image)
{
    exr_stream stream = { .ctx = ctx, .path = path, .data = data, .size = size };
    exr_active = &stream;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_error_handler;
    init.user_data = &stream;
    init.read_fn = exr_read_memory;
    init.size_fn = exr_size_memory;
    init.max_image_width = DRIFT_IMAGE_MAX_DIMENSION;
    init.max_image_height = DRIFT_IMAGE_MAX_DIMENSION;
    init.max_tile_width = DRIFT_IMAGE_MAX_DIMENSION;
    init.max_tile_height = DRIFT_IMAGE_MAX_DIMENSION;
    // A truncated file is an error, not something to patch up from the chunks that remain.
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;

    exr_context_t f = NULL;
    exr_result_t rv = exr_start_read(&f, path, &init);
    if (rv != EXR_ERR_SUCCESS) {
        exr_finish(&f);
        return exr_fail(&stream, rv, "not a readable OpenEXR file");
    }

    // Choose the part and its channels.
    int part_count = 0;
    rv = exr_get_count(f, &part_count);
    int part = -1;
    exr_storage_t storage = EXR_STORAGE_LAST_TYPE;
    channel_pick pick = { { -1, -1, -1 }, false };
    const exr_attr_chlist_t *list = NULL;
    for (int p = 0; rv == EXR_ERR_SUCCESS && p < part_count && part < 0; ++p) {
        exr_storage_t st;
        if (exr_get_storage(f, p, &st) != EXR_ERR_SUCCESS ||
            (st != EXR_STORAGE_SCANLINE && st != EXR_STORAGE_TILED)) {
            continue;
        }
        if (exr_get_channels(f, p, &list) == EXR_ERR_SUCCESS && list &&
            pick_channels(list, &pick)) {
            part = p;
            storage = st;
        }
    }
    if (rv != EXR_ERR_SUCCESS) {
        exr_finish(&f);
        return exr_fail(&stream, rv, "cannot read OpenEXR header");
    }
    if (part < 0) {
        exr_finish(&f);
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_UNSUPPORTED, path, 0,
                  "no flat (non-deep) part with R,G,B or Y channels");
        return DRIFT_ERR_UNSUPPORTED;
    }
    for (int k = 0; k < 3; ++k) {
        const exr_attr_chlist_entry_t *e =
            pick.index[k] >= 0 ? &list->entries[pick.index[k]] : NULL;
        if (e && (e->x_sampling != 1 || e->y_sampling != 1)) {
            // Log before exr_finish: the channel list belongs to the context.
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_UNSUPPORTED, path, 0,
                      "channel %s is subsampled (%dx%d); not supported", e->name.str, e->x_sampling,
                      e->y_sampling);
            exr_finish(&f);
            return DRIFT_ERR_UNSUPPORTED;
        }
    }

    exr_attr_box2i_t dw;
    rv = exr_get_data_window(f, part, &dw);
    if (rv != EXR_ERR_SUCCESS) {
        exr_finish(&f);
        return exr_fail(&stream, rv, "cannot read data window");
    }
    int64_t width = (int64_t)dw.max.x - dw.min.x + 1;
    int64_t height = (int64_t)dw.max.y - dw.min.y + 1;
    if (width <= 0 || height <= 0 || width > DRIFT_IMAGE_MAX_DIMENSION ||
        height > DRIFT_IMAGE_MAX_DIMENSION) {
        exr_finish(&f);
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, path, 0,
                  "data window is %lldx%lld; the limit is %d per side", (long long)width,
                  (long long)height, DRIFT_IMAGE_MAX_DIMENSION);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }

    // The float image is allocated (and zeroed) before any chunk is read, so a forged header
    // could make a tiny file cost gigabytes. OpenEXR's codecs are bounded in expansion (deflate
    // 1032:1; flat-image PIZ/DWA can go further), so allow 4096:1 on top of a 256 MiB floor
    // and call anything beyond corrupt.
    uint64_t decoded = (uint64_t)width * (uint64_t)height * 3u * sizeof(float);
    if (decoded > ((uint64_t)256 << 20) + (uint64_t)size * 4096u) {
        exr_finish(&f);
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, 0,
                  "corrupt OpenEXR file: a %lldx%lld image cannot fit in %zu bytes",
                  (long long)width, (long long)height, size);
        return DRIFT_ERR_PARSE;
    }
    drift_image img;
    drift_result r = drift_image_create(ctx, (int32_t)width, (int32_t)height, 3, &img);
    if (r != DRIFT_OK) {
        exr_finish(&f);
        return r;
    }
    exr_compression_t compression = EXR_COMPRESSION_NONE;
    rv = exr_get_compression(f, part, &compression);
    if (rv == EXR_ERR_SUCCESS &&
        (compression == EXR_COMPRESSION_DWAA || compression == EXR_COMPRESSION_DWAB)) {
        const char *names[3] = { NULL, NULL, NULL };
        for (int k = 0; k < 3; ++k) {
            names[k] = pick.index[k] >= 0 ? list->entries[pick.index[k]].name.str : NULL;
        }
        if (drift__exr_dwa_decode(path, data, size, part, names, img.pixels, img.stride, img.width,
                                  img.height, stream.message, sizeof(stream.message)) != 0) {
            exr_finish(&f);
            drift_image_destroy(ctx, &img);
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, 0,
                      "corrupt %s-compressed OpenEXR pixel data: %s",
                      compression == EXR_COMPRESSION_DWAA ? "DWAA" : "DWAB", stream.message);
            return DRIFT_ERR_PARSE;
        }
    } else if (rv == EXR_ERR_SUCCESS) {
        rv = decode_part(f, part, storage, &dw, &pick, &img);
    }
    if (rv != EXR_ERR_SUCCESS) {
        r = exr_fail(&stream, rv, "corrupt OpenEXR pixel data");
        exr_finish(&f);
        drift_image_destroy(ctx, &img);
        return r;
    }
    exr_finish(&f);
    if (pick.grey) {
        for (int32_t y = 0; y < img.height; ++y) {
            for (int32_t x = 0; x < img.width; ++x) {
                float *p = drift_image_pixel(&img, x, y);
                p[1] = p[0];
                p[2] = p[0];
            }
        }
    }
    *out_image = img;
    return DRIFT_OK;
}

drift_result drift__image_exr_load(drift_context *ctx, const char *path, const uint8_t *data,
                                   size_t size, drift_image *out_image)
{
    drift_result r = exr_load(ctx, path, data, size, out_image);
    exr_active = NULL;
    return r;
}

// --- SAVING ---

typedef struct out_channel {
    char name[256];
    const drift_image *image;
    int component;
} out_channel;

static const char *const channel_names[4][4] = {
    { "Y" }, { "Y", "A" }, { "R", "G", "B" }, { "R", "G", "B", "A" }
};

// The name of channel `c` of a layer (its `channels` list, or the defaults) into out[32];
// false when the list has no c-th name, or one past 30 bytes. out may be NULL.
static bool channel_suffix(const drift_image_layer *layer, const char *list, int c, char *out)
{
    if (!list) {
        if (out) {
            snprintf(out, 32, "%s", channel_names[layer->image->channels - 1][c]);
        }
        return true;
    }
    const char *p = list;
    for (int k = 0; k < c && p; ++k) {
        p = strchr(p, ',');
        p = p ? p + 1 : NULL;
    }
    const char *end = p ? strchr(p, ',') : NULL;
    size_t n = !p ? 0 : end ? (size_t)(end - p) : strlen(p);
    if (n == 0 || n > 30 || (c == layer->image->channels - 1 && end)) {
        return false;
    }
    if (out) {
        snprintf(out, 32, "%.*s", (int)n, p);
    }
    return true;
}

static drift_result check_layers(drift_context *ctx, const char *path,
                                 const drift_image_layer *layers, uint32_t layer_count,
                                 const char *const *names, size_t *out_channel_count)
{
    if (!path || !layers || layer_count == 0) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, path, 0,
                  "drift_image_save_exr: no layers");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    size_t channels = 0;
    for (uint32_t i = 0; i < layer_count; ++i) {
        const drift_image *im = layers[i].image;
        const char *name = layers[i].name ? layers[i].name : "";
        if (!drift_image_is_valid(im) || im->width != layers[0].image->width ||
            im->height != layers[0].image->height || strlen(name) > 200) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, path, 0,
                      "layer %u ('%s'): invalid image, size differs from layer 0 or name "
                      "too long",
                      i, name);
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
        const char *list = names ? names[i] : NULL;
        bool named = true;
        for (int c = 0; list && c < im->channels; ++c) {
            named = named && channel_suffix(&layers[i], list, c, NULL);
        }
        if (!named) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, path, 0,
                      "layer %u ('%s'): channels '%s' do not name its %d channels", i, name, list,
                      im->channels);
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
        for (uint32_t j = 0; j < i; ++j) {
            // Layers with their own channel names may share one ("" for Z beside R, G, B):
            // their channels are checked for collisions one by one.
            if (!list && !(names && names[j]) &&
                strcmp(name, layers[j].name ? layers[j].name : "") == 0) {
                drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, path, 0,
                          "layers %u and %u share the name '%s'", j, i, name);
                return DRIFT_ERR_INVALID_ARGUMENT;
            }
        }
        channels += (size_t)im->channels;
    }
    *out_channel_count = channels;
    return DRIFT_OK;
}

// OpenEXR 3.1.5's ZIP encoder falls back to the raw chunk only when deflate's output is
// longer than it, and keeps output of exactly the raw size. But a chunk whose data size equals
// its uncompressed size is raw by the file format, so every reader (OpenEXRCore, the C++
// library) would take those deflate bytes for pixels. Wrapped around the library's compressor,
// this stores the packed (raw) chunk whenever compression does not make it smaller.
typedef struct exr_compress_hook {
    exr_result_t (*compress)(exr_encode_pipeline_t *encoder);
} exr_compress_hook;

static exr_result_t compress_or_store_raw(exr_encode_pipeline_t *encoder)
{
    const exr_compress_hook *hook = encoder->encoding_user_data;
    exr_result_t rv = hook->compress(encoder);
    if (rv != EXR_ERR_SUCCESS || encoder->compressed_bytes < encoder->packed_bytes ||
        encoder->compressed_buffer == encoder->packed_buffer) {
        return rv;
    }
    if (!encoder->compressed_buffer || encoder->compressed_alloc_size < encoder->packed_bytes) {
        return EXR_ERR_CORRUPT_CHUNK; // cannot happen: the output was at least this long
    }
    memcpy(encoder->compressed_buffer, encoder->packed_buffer, (size_t)encoder->packed_bytes);
    encoder->compressed_bytes = encoder->packed_bytes;
    return EXR_ERR_SUCCESS;
}

static exr_result_t encode_all(exr_context_t f, int part, const out_channel *chans,
                               size_t chan_count, int32_t height)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(f, part, &lines);
    if (rv == EXR_ERR_SUCCESS && lines <= 0) {
        rv = EXR_ERR_INVALID_ATTR;
    }
    exr_encode_pipeline_t encoder = EXR_ENCODE_PIPELINE_INITIALIZER;
    exr_compress_hook hook = { NULL };
    bool first = true;
    for (int32_t y = 0; rv == EXR_ERR_SUCCESS && y < height; y += lines) {
        exr_chunk_info_t cinfo = { 0 };
        rv = exr_write_scanline_chunk_info(f, part, y, &cinfo);
        if (rv != EXR_ERR_SUCCESS) {
            break;
        }
        rv = first ? exr_encoding_initialize(f, part, &cinfo, &encoder)
                   : exr_encoding_update(f, part, &cinfo, &encoder);
        if (rv != EXR_ERR_SUCCESS) {
            break;
        }
        for (int c = 0; c < encoder.channel_count; ++c) {
            exr_coding_channel_info_t *ch = &encoder.channels[c];
            const out_channel *src = NULL;
            for (size_t k = 0; k < chan_count && !src; ++k) {
                if (strcmp(chans[k].name, ch->channel_name) == 0) {
                    src = &chans[k];
                }
            }
            if (!src) {
                rv = EXR_ERR_INVALID_ARGUMENT;
                break;
            }
            const drift_image *im = src->image;
            ch->encode_from_ptr =
                (const uint8_t *)(drift_image_pixel(im, 0, cinfo.start_y) + src->component);
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = (int16_t)sizeof(float);
            ch->user_pixel_stride = (int32_t)(sizeof(float) * (size_t)im->channels);
            ch->user_line_stride = (int32_t)(sizeof(float) * (size_t)im->stride);
        }
        if (rv == EXR_ERR_SUCCESS && first) {
            rv = exr_encoding_choose_default_routines(f, part, &encoder);
            if (rv == EXR_ERR_SUCCESS && encoder.compress_fn) {
                hook.compress = encoder.compress_fn;
                encoder.compress_fn = compress_or_store_raw;
                encoder.encoding_user_data = &hook;
            }
        }
        if (rv == EXR_ERR_SUCCESS) {
            rv = exr_encoding_run(f, part, &encoder);
        }
        first = false;
    }
    exr_result_t drv = first ? EXR_ERR_SUCCESS : exr_encoding_destroy(f, &encoder);
    return rv != EXR_ERR_SUCCESS ? rv : drv;
}

drift_result drift_image_save_exr(drift_context *ctx, const char *path,
                                  const drift_image_layer *layers, uint32_t layer_count)
{
    return drift_image_save_exr_attributes(ctx, path, layers, layer_count, NULL, 0);
}

drift_result drift_image_save_exr_attributes(drift_context *ctx, const char *path,
                                             const drift_image_layer *layers, uint32_t layer_count,
                                             const drift_image_attribute *attributes,
                                             uint32_t attribute_count)
{
    return drift_image_save_exr_channels(ctx, path, layers, layer_count, NULL, attributes,
                                         attribute_count);
}

drift_result drift_image_save_exr_channels(drift_context *ctx, const char *path,
                                           const drift_image_layer *layers, uint32_t layer_count,
                                           const char *const *channels,
                                           const drift_image_attribute *attributes,
                                           uint32_t attribute_count)
{
    size_t chan_count = 0;
    drift_result r = check_layers(ctx, path, layers, layer_count, channels, &chan_count);
    if (r != DRIFT_OK) {
        return r;
    }
    size_t bytes;
    if (!drift_size_mul(chan_count, sizeof(out_channel), &bytes)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    out_channel *chans = drift_alloc(ctx, bytes);
    if (!chans) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    size_t n = 0;
    for (uint32_t i = 0; i < layer_count; ++i) {
        const char *name = layers[i].name ? layers[i].name : "";
        const drift_image *im = layers[i].image;
        for (int c = 0; c < im->channels; ++c) {
            char suffix[32];
            channel_suffix(&layers[i], channels ? channels[i] : NULL, c, suffix);
            snprintf(chans[n].name, sizeof(chans[n].name), "%s%s%s", name, name[0] ? "." : "",
                     suffix);
            chans[n].image = im;
            chans[n].component = c;
            ++n;
        }
    }
    // Distinct layer names can still collide on channel names ("a" with Y vs "a.Y" default...).
    for (size_t i = 0; i < chan_count; ++i) {
        for (size_t j = 0; j < i; ++j) {
            if (strcmp(chans[i].name, chans[j].name) == 0) {
                drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, path, 0,
                          "two layers produce the channel '%s'", chans[i].name);
                drift_free(ctx, chans);
                return DRIFT_ERR_INVALID_ARGUMENT;
            }
        }
    }

    drift__image_temp temp;
    r = drift__image_temp_open(ctx, path, &temp);
    if (r != DRIFT_OK) {
        drift_free(ctx, chans);
        return r;
    }
    exr_stream stream = { .ctx = ctx, .path = path, .temp = &temp };
    exr_active = &stream;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_error_handler;
    init.user_data = &stream;
    init.write_fn = exr_write_temp;

    exr_context_t f = NULL;
    int part = 0;
    int32_t width = layers[0].image->width, height = layers[0].image->height;
    exr_result_t rv = exr_start_write(&f, temp.temp_path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS) {
        rv = exr_add_part(f, NULL, EXR_STORAGE_SCANLINE, &part);
    }
    if (rv == EXR_ERR_SUCCESS) {
        rv = exr_initialize_required_attr_simple(f, part, width, height, EXR_COMPRESSION_ZIP);
    }
    for (size_t i = 0; rv == EXR_ERR_SUCCESS && i < chan_count; ++i) {
        rv = exr_add_channel(f, part, chans[i].name, EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC,
                             1, 1);
    }
    if (rv == EXR_ERR_SUCCESS) { // linear Rec.709 primaries, D65 white (ITU-R BT.709)
        const exr_attr_chromaticities_t rec709 = { 0.64f, 0.33f, 0.30f,   0.60f,
                                                   0.15f, 0.06f, 0.3127f, 0.3290f };
        rv = exr_attr_set_chromaticities(f, part, "chromaticities", &rec709);
    }
    for (uint32_t i = 0; rv == EXR_ERR_SUCCESS && i < attribute_count; ++i) {
        rv = exr_attr_set_string(f, part, attributes[i].name, attributes[i].value);
    }
    if (rv == EXR_ERR_SUCCESS) {
        rv = exr_write_header(f);
    }
    if (rv == EXR_ERR_SUCCESS) {
        rv = encode_all(f, part, chans, chan_count, height);
    }
    // exr_finish writes the chunk offset table, so its result matters too.
    exr_result_t frv = exr_finish(&f);
    if (rv == EXR_ERR_SUCCESS) {
        rv = frv;
    }
    if (rv != EXR_ERR_SUCCESS) {
        r = exr_fail(&stream, rv, "OpenEXR write failed");
    }
    exr_active = NULL;
    drift_free(ctx, chans);
    return drift__image_temp_close(ctx, &temp, r);
}

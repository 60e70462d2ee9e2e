// Image file I/O front end: extension dispatch, whole-file reads, the stb back end (PNG, JPEG,
// Radiance HDR) and the temp-file-then-rename protocol every writer follows.
//
// The stb implementation is not compiled here: Debian's libstb (pkg-config stb, -lstb) already
// contains stb_image and stb_image_write, so only the declarations are included.
#include "drift/file.h"
#include "drift/math.h"
#include "image_io_internal.h"
#include "image_ocio.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

typedef enum image_format {
    FORMAT_UNKNOWN = 0,
    FORMAT_EXR,
    FORMAT_PNG,
    FORMAT_JPEG,
    FORMAT_HDR,
} image_format;

static int lower_ascii(int c)
{
    return c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c;
}

static bool extension_is(const char *ext, const char *want)
{
    for (; *ext && *want; ++ext, ++want) {
        if (lower_ascii((unsigned char)*ext) != *want) {
            return false;
        }
    }
    return *ext == '\0' && *want == '\0';
}

static image_format format_from_path(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    if (!dot) {
        return FORMAT_UNKNOWN;
    }
    const char *ext = dot + 1;
    if (extension_is(ext, "exr")) {
        return FORMAT_EXR;
    }
    if (extension_is(ext, "png")) {
        return FORMAT_PNG;
    }
    if (extension_is(ext, "jpg") || extension_is(ext, "jpeg")) {
        return FORMAT_JPEG;
    }
    if (extension_is(ext, "hdr")) {
        return FORMAT_HDR;
    }
    return FORMAT_UNKNOWN;
}

const char *drift__errno_text(int err, char *buf, size_t cap)
{
    // XSI strerror_r (we build with _POSIX_C_SOURCE=200809L) fills buf and returns int;
    // plain strerror is not thread-safe.
    if (strerror_r(err, buf, cap) != 0) {
        snprintf(buf, cap, "error %d", err);
    }
    return buf;
}

const char *drift__write_errno_text(int err, char *buf, size_t cap)
{
    char os[96]; // with the plain words it fits the callers' 128 bytes
    drift__errno_text(err, os, sizeof(os));
    const char *plain = err == ENOSPC || err == EDQUOT ? "disk full"
                        : err == EFBIG                 ? "file size limit reached"
                                                       : NULL;
    if (plain) {
        snprintf(buf, cap, "%s (%s)", plain, os);
    } else {
        snprintf(buf, cap, "%s", os);
    }
    return buf;
}

// --- WHOLE-FILE READS ---

drift_result drift__image_read_file(drift_context *ctx, const char *path, uint8_t **out_data,
                                    size_t *out_size)
{
    *out_data = NULL;
    *out_size = 0;
    char why[128];
    int fd = drift_input_open(path, why, sizeof(why));
    if (fd < 0) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, path, 0, "cannot open image: %s", why);
        return DRIFT_ERR_IO;
    }
    struct stat st;
    if (fstat(fd, &st) != 0) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, path, 0, "cannot open image: %s",
                  drift__errno_text(errno, why, sizeof(why)));
        close(fd);
        return DRIFT_ERR_IO;
    }
    size_t size = (size_t)st.st_size;
    // One extra byte so an empty file still gets a non-NULL buffer.
    uint8_t *data = drift_alloc(ctx, size + 1);
    if (!data) {
        close(fd);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    size_t done = 0;
    while (done < size) {
        ssize_t n = read(fd, data + done, size - done);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n <= 0) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, path, 0, "read failed: %s",
                      n < 0 ? drift__errno_text(errno, why, sizeof(why))
                            : "file shrank while reading");
            drift_free(ctx, data);
            close(fd);
            return DRIFT_ERR_IO;
        }
        done += (size_t)n;
    }
    close(fd);
    *out_data = data;
    *out_size = size;
    return DRIFT_OK;
}

// --- TEMP FILE, THEN RENAME ---

drift_result drift__image_temp_open(drift_context *ctx, const char *path, drift__image_temp *out)
{
    *out = (drift__image_temp){ .fd = -1, .path = path };
    char why[128];
    // The name only has to be unlikely to collide; O_EXCL makes a collision a retry, not a
    // clobber. Keyed on time, pid and the address of *out so concurrent writers differ.
    uint32_t key = drift_hash_combine((uint32_t)getpid(), (uint32_t)(uintptr_t)out);
    key = drift_hash_combine(key, (uint32_t)(drift_time_now() * 1e9));
    for (int attempt = 0; attempt < 64; ++attempt) {
        uint32_t tag = drift_hash_combine(key, (uint32_t)attempt);
        int n = snprintf(out->temp_path, sizeof(out->temp_path), "%s.tmp-%08x", path, tag);
        if (n < 0 || (size_t)n >= sizeof(out->temp_path)) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, path, 0, "path too long");
            return DRIFT_ERR_IO;
        }
        int fd = open(out->temp_path, O_WRONLY | O_CREAT | O_EXCL, 0666);
        if (fd >= 0) {
            out->fd = fd;
            return DRIFT_OK;
        }
        if (errno != EEXIST) {
            break;
        }
    }
    drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, path, 0, "cannot create file: %s",
              drift__errno_text(errno, why, sizeof(why)));
    out->temp_path[0] = '\0';
    return DRIFT_ERR_IO;
}

// DRIFT_TEST_DISK_FULL: the bytes this process may still write, -1 when unset (parsed once).
static _Atomic long long disk_full_left = -2;

static bool disk_full_injected(size_t size)
{
    long long left = disk_full_left;
    if (left == -2) {
        const char *env = getenv("DRIFT_TEST_DISK_FULL");
        left = env && *env ? atoll(env) : -1;
        disk_full_left = left;
    }
    if (left < 0) {
        return false;
    }
    if ((unsigned long long)left < size) {
        errno = ENOSPC;
        return true;
    }
    disk_full_left = left - (long long)size;
    return false;
}

bool drift__image_temp_write(drift__image_temp *t, const void *data, size_t size, uint64_t offset)
{
    const uint8_t *p = data;
    if (disk_full_injected(size)) {
        return false;
    }
    while (size > 0) {
        ssize_t n = pwrite(t->fd, p, size, (off_t)offset);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n <= 0) {
            if (n == 0) {
                errno = EIO;
            }
            return false;
        }
        p += n;
        size -= (size_t)n;
        offset += (uint64_t)n;
    }
    return true;
}

drift_result drift__image_temp_close(drift_context *ctx, drift__image_temp *t, drift_result result)
{
    char why[128];
    if (t->fd >= 0) {
        // close() can report a delayed write error (NFS, full disk); it counts as a failure.
        if (close(t->fd) != 0 && result == DRIFT_OK) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, t->path, 0, "write failed: %s",
                      drift__write_errno_text(errno, why, sizeof(why)));
            result = DRIFT_ERR_IO;
        }
        t->fd = -1;
    }
    if (result == DRIFT_OK && rename(t->temp_path, t->path) != 0) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, t->path, 0, "cannot rename %s: %s",
                  t->temp_path, drift__errno_text(errno, why, sizeof(why)));
        result = DRIFT_ERR_IO;
    }
    if (result != DRIFT_OK && t->temp_path[0]) {
        unlink(t->temp_path);
    }
    t->temp_path[0] = '\0';
    return result;
}

// --- STB BACK END (PNG, JPEG, HDR) ---

// Whether a Radiance HDR file holds all the scanlines its header promises: stb_image decodes
// a cut file without complaint (the rest comes out black). Walks the header (lines up to an
// empty one), the resolution line and each scanline, flat (4 bytes a pixel) or new-style
// RLE (2, 2, width; then per channel runs of a repeated byte (count > 128) or literals).
static bool hdr_is_complete(const uint8_t *data, size_t size, int width)
{
    size_t at = 0;
    int height = 0, w = 0;
    bool blank = false;
    while (!blank) { // header lines
        size_t start = at;
        while (at < size && data[at] != '\n') {
            ++at;
        }
        if (at++ >= size) {
            return false;
        }
        blank = at - start == 1;
    }
    char res[64];
    size_t n = 0;
    while (at < size && data[at] != '\n' && n + 1 < sizeof res) {
        res[n++] = (char)data[at++];
    }
    res[n] = '\0';
    if (at++ >= size || sscanf(res, "-Y %d +X %d", &height, &w) != 2 || w != width) {
        return true; // a layout stb_image reads otherwise: leave it to the decoder
    }
    for (int y = 0; y < height; ++y) {
        bool rle = width >= 8 && width < 32768 && at + 4 <= size && data[at] == 2 &&
                   data[at + 1] == 2 && !(data[at + 2] & 0x80) &&
                   ((int)data[at + 2] << 8 | data[at + 3]) == width;
        if (!rle) {
            if (size - at < (size_t)width * 4) {
                return false;
            }
            at += (size_t)width * 4;
            continue;
        }
        at += 4;
        for (int c = 0; c < 4; ++c) {
            for (int x = 0; x < width;) {
                if (at >= size) {
                    return false;
                }
                int count = data[at++];
                bool run = count > 128;
                count = run ? count - 128 : count;
                if (count == 0 || x + count > width) {
                    return true; // corrupt: stb_image says so itself
                }
                size_t bytes = run ? 1 : (size_t)count;
                if (size - at < bytes) {
                    return false;
                }
                at += bytes;
                x += count;
            }
        }
    }
    return true;
}

// stb stops at the last IDAT it needs and never looks at the end of the file, so a PNG cut
// inside its final chunk would load. A complete file ends its chunk list with IEND (length 0,
// type, CRC); trailing bytes after it are tolerated.
static bool png_has_end(const uint8_t *data, size_t size)
{
    if (size < 8 + 12) {
        return false;
    }
    for (size_t i = size - 12;; --i) {
        if (data[i] == 0 && data[i + 1] == 0 && data[i + 2] == 0 && data[i + 3] == 0 &&
            memcmp(data + i + 4, "IEND", 4) == 0) {
            return true;
        }
        if (i == 8) {
            return false;
        }
    }
}

// The format the bytes themselves are, by their signature (PNG's eight bytes, JPEG's start of
// image, Radiance's "#?"), or FORMAT_UNKNOWN. stb would decode anything it knows (PNM, BMP,
// GIF, TGA, PSD) behind any name, and its 16-bit PNM converts channels into too short a
// buffer (found by fuzz_image_load): only what the extension says is decoded.
static image_format content_format(const uint8_t *data, size_t size)
{
    static const uint8_t png[8] = { 0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n' };
    if (size >= sizeof png && memcmp(data, png, sizeof png) == 0) {
        return FORMAT_PNG;
    }
    if (size >= 3 && data[0] == 0xff && data[1] == 0xd8 && data[2] == 0xff) {
        return FORMAT_JPEG;
    }
    if (size <= (size_t)INT_MAX && stbi_is_hdr_from_memory(data, (int)size)) {
        return FORMAT_HDR;
    }
    return FORMAT_UNKNOWN;
}

static const char *format_name(image_format format)
{
    switch (format) {
    case FORMAT_PNG:
        return "PNG";
    case FORMAT_JPEG:
        return "JPEG";
    case FORMAT_HDR:
        return "Radiance HDR";
    default:
        return "not PNG, JPEG or Radiance HDR";
    }
}

// What a load reads: the colour (sRGB-decoded, 3 channels), or a coverage (1 channel, values
// as stored): the alpha channel, or where the file has none 1 (ALPHA_CHANNEL) or its grey
// value (ALPHA_OR_GREY).
typedef enum image_content {
    CONTENT_COLOUR,
    CONTENT_ALPHA_CHANNEL,
    CONTENT_ALPHA_OR_GREY
} image_content;

static drift_result stb_load(drift_context *ctx, const char *path, image_format format,
                             const uint8_t *data, size_t size, image_content content_kind,
                             drift_image *out_image)
{
    bool alpha = content_kind != CONTENT_COLOUR;
    if (size > (size_t)INT_MAX) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_UNSUPPORTED, path, 0, "file over 2 GiB");
        return DRIFT_ERR_UNSUPPORTED;
    }
    int len = (int)size;
    image_format content = content_format(data, size);
    if (content != format) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, 0,
                  "content does not match the extension (%s data)", format_name(content));
        return DRIFT_ERR_PARSE;
    }
    int width = 0, height = 0, file_channels = 0;
    // Header first, so the size is checked before stb allocates the pixels.
    if (!stbi_info_from_memory(data, len, &width, &height, &file_channels)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, 0, "not a readable image: %s",
                  stbi_failure_reason() ? stbi_failure_reason() : "unknown format");
        return DRIFT_ERR_PARSE;
    }
    if (width <= 0 || height <= 0 || width > DRIFT_IMAGE_MAX_DIMENSION ||
        height > DRIFT_IMAGE_MAX_DIMENSION) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, path, 0,
                  "image is %dx%d; the limit is %d per side", width, height,
                  DRIFT_IMAGE_MAX_DIMENSION);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (format == FORMAT_PNG && !png_has_end(data, size)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, 0,
                  "truncated PNG: no complete IEND chunk");
        return DRIFT_ERR_PARSE;
    }
    bool is_hdr = format == FORMAT_HDR;
    if (is_hdr && !hdr_is_complete(data, size, width)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, 0,
                  "truncated Radiance HDR: the file ends before its %d scanlines do", height);
        return DRIFT_ERR_PARSE;
    }
    if (format == FORMAT_PNG) {
        // Deflate expands at most 1032:1, and every row holds a filter byte plus at least one
        // bit per pixel. A header promising more than the file can hold is corrupt; refusing
        // it here keeps a 60-byte file from costing gigabytes.
        uint64_t raw_min = (uint64_t)height * (1u + ((uint64_t)width + 7u) / 8u);
        if (raw_min > (uint64_t)size * 1032u) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, 0,
                      "corrupt PNG: a %dx%d image cannot fit in %zu bytes", width, height, size);
            return DRIFT_ERR_PARSE;
        }
    }
    // Decode first, then allocate the float image, so corrupt files cost no float buffer.
    // For the alpha, stb decodes RGBA (grey+alpha and opaque files too) and the fourth
    // channel is kept.
    int decoded = alpha ? 4 : 3, kept = alpha ? 1 : 3;
    size_t count = (size_t)width * (size_t)height * (size_t)kept;
    int w = 0, h = 0, n = 0;
    void *pixels = NULL;
    bool wide = false;
    if (is_hdr) {
        pixels = stbi_loadf_from_memory(data, len, &w, &h, &n, decoded);
    } else if (format == FORMAT_PNG && stbi_is_16_bit_from_memory(data, len)) {
        pixels = stbi_load_16_from_memory(data, len, &w, &h, &n, decoded);
        wide = true;
    } else {
        pixels = stbi_load_from_memory(data, len, &w, &h, &n, decoded);
    }
    if (!pixels || w != width || h != height) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, 0, "corrupt image: %s",
                  stbi_failure_reason() ? stbi_failure_reason() : "decoder failed");
        stbi_image_free(pixels);
        return DRIFT_ERR_PARSE;
    }
    drift_image img;
    drift_result r = drift_image_create(ctx, width, height, kept, &img);
    if (r != DRIFT_OK) {
        stbi_image_free(pixels);
        return r;
    }
    if (alpha) {
        // n is the file's own channel count: 2 and 4 carry alpha.
        bool grey = content_kind == CONTENT_ALPHA_OR_GREY && n != 2 && n != 4;
        for (size_t i = 0; i < count; ++i) {
            float v[4];
            for (int c = 0; c < 4; ++c) {
                v[c] = is_hdr ? ((const float *)pixels)[4 * i + (size_t)c]
                       : wide ? (float)((const uint16_t *)pixels)[4 * i + (size_t)c] / 65535.0f
                              : (float)((const uint8_t *)pixels)[4 * i + (size_t)c] / 255.0f;
            }
            img.pixels[i] = grey ? (v[0] + v[1] + v[2]) / 3.0f : v[3];
        }
    } else if (is_hdr) {
        memcpy(img.pixels, pixels, count * sizeof(float));
    } else if (wide) {
        const uint16_t *p16 = pixels;
        for (size_t i = 0; i < count; ++i) {
            img.pixels[i] = drift_srgb_to_linear((float)p16[i] * (1.0f / 65535.0f));
        }
    } else {
        const uint8_t *p8 = pixels;
        float lut[256];
        for (int i = 0; i < 256; ++i) {
            lut[i] = drift_srgb_to_linear((float)i * (1.0f / 255.0f));
        }
        for (size_t i = 0; i < count; ++i) {
            img.pixels[i] = lut[p8[i]];
        }
    }
    stbi_image_free(pixels);
    *out_image = img;
    return DRIFT_OK;
}

// --- PUBLIC ---

// An EXR's alpha is not read: glTF's and MTL's alpha textures are PNG or JPEG.
static drift_result exr_alpha_refused(drift_context *ctx, const char *name)
{
    drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_UNSUPPORTED, name, 0,
              "alpha is read from PNG, JPEG or Radiance HDR images, not OpenEXR");
    return DRIFT_ERR_UNSUPPORTED;
}

static drift_result load_file(drift_context *ctx, const char *path, image_content content_kind,
                              drift_image *out_image)
{
    bool alpha = content_kind != CONTENT_COLOUR;
    if (!out_image) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_image = (drift_image){ 0 };
    if (!path) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    image_format format = format_from_path(path);
    if (format == FORMAT_UNKNOWN) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_UNSUPPORTED, path, 0,
                  "unsupported image extension (use .exr, .png, .jpg, .jpeg or .hdr)");
        return DRIFT_ERR_UNSUPPORTED;
    }
    if (format == FORMAT_EXR && alpha) {
        return exr_alpha_refused(ctx, path);
    }
    uint8_t *data = NULL;
    size_t size = 0;
    drift_result r = drift__image_read_file(ctx, path, &data, &size);
    if (r != DRIFT_OK) {
        return r;
    }
    if (format == FORMAT_EXR) {
        r = drift__image_exr_load(ctx, path, data, size, out_image);
    } else {
        r = stb_load(ctx, path, format, data, size, content_kind, out_image);
    }
    drift_free(ctx, data);
    return r;
}

static drift_result load_memory(drift_context *ctx, const char *name, const void *data, size_t size,
                                image_content content_kind, drift_image *out_image)
{
    bool alpha = content_kind != CONTENT_COLOUR;
    if (!out_image) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_image = (drift_image){ 0 };
    if (!name || !data) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    static const uint8_t exr_magic[4] = { 0x76, 0x2f, 0x31, 0x01 };
    if (size >= 4 && memcmp(data, exr_magic, 4) == 0) {
        return alpha ? exr_alpha_refused(ctx, name)
                     : drift__image_exr_load(ctx, name, data, size, out_image);
    }
    image_format format = content_format(data, size);
    if (format == FORMAT_UNKNOWN) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_UNSUPPORTED, name, 0,
                  "image data is not PNG, JPEG, Radiance HDR or OpenEXR");
        return DRIFT_ERR_UNSUPPORTED;
    }
    return stb_load(ctx, name, format, data, size, content_kind, out_image);
}

drift_result drift_image_load(drift_context *ctx, const char *path, drift_image *out_image)
{
    return load_file(ctx, path, CONTENT_COLOUR, out_image);
}

drift_result drift_image_load_memory(drift_context *ctx, const char *name, const void *data,
                                     size_t size, drift_image *out_image)
{
    return load_memory(ctx, name, data, size, CONTENT_COLOUR, out_image);
}

static image_content alpha_content(drift_alpha_source source)
{
    return source == DRIFT_ALPHA_OR_GREY ? CONTENT_ALPHA_OR_GREY : CONTENT_ALPHA_CHANNEL;
}

drift_result drift_image_load_alpha(drift_context *ctx, const char *path, drift_alpha_source source,
                                    drift_image *out_image)
{
    return load_file(ctx, path, alpha_content(source), out_image);
}

drift_result drift_image_load_alpha_memory(drift_context *ctx, const char *name, const void *data,
                                           size_t size, drift_alpha_source source,
                                           drift_image *out_image)
{
    return load_memory(ctx, name, data, size, alpha_content(source), out_image);
}

typedef struct png_sink {
    drift__image_temp *temp;
    uint64_t offset;
    bool failed;
    int error;
} png_sink;

static void png_write_bytes(png_sink *sink, const void *data, size_t size)
{
    if (sink->failed) {
        return;
    }
    if (!drift__image_temp_write(sink->temp, data, size, sink->offset)) {
        sink->failed = true;
        sink->error = errno;
        return;
    }
    sink->offset += (uint64_t)size;
}

// stb writes the whole file in one call: its signature and IHDR chunk (33 bytes), then the
// rest. An sRGB chunk (rendering intent 0, perceptual) goes between them, where the PNG spec
// wants it (before IDAT), so viewers and browsers take the 8-bit values as sRGB.
static void png_write(void *context, void *data, int size)
{
    png_sink *sink = context;
    if (sink->failed || size <= 0) {
        return;
    }
    static const uint8_t srgb_chunk[13] = {
        0, 0, 0, 1, 's', 'R', 'G', 'B', 0, 0xae, 0xce, 0x1c, 0xe9
    }; // length, type, 0, CRC
    const uint8_t *bytes = data;
    if (sink->offset == 0 && size > 33 && memcmp(bytes + 12, "IHDR", 4) == 0) {
        png_write_bytes(sink, bytes, 33);
        png_write_bytes(sink, srgb_chunk, sizeof srgb_chunk);
        png_write_bytes(sink, bytes + 33, (size_t)size - 33);
        return;
    }
    png_write_bytes(sink, data, (size_t)size);
}

drift_result drift_image_save_png(drift_context *ctx, const char *path, const drift_image *image,
                                  const drift_tonemap_params *tonemap)
{
    if (!path || !drift_image_is_valid(image)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, path, 0,
                  "drift_image_save_png: invalid image");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    size_t bytes;
    if (!drift_size_mul((size_t)image->width * (size_t)image->height, 3, &bytes) ||
        (size_t)image->width * 3 > (size_t)INT_MAX) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    uint8_t *rgb = drift_alloc(ctx, bytes);
    if (!rgb) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_image_tonemap(image, tonemap, rgb);

    drift__image_temp temp;
    drift_result r = drift__image_temp_open(ctx, path, &temp);
    if (r == DRIFT_OK) {
        png_sink sink = { .temp = &temp };
        int ok = stbi_write_png_to_func(png_write, &sink, image->width, image->height, 3, rgb,
                                        image->width * 3);
        if (!ok || sink.failed) {
            char why[160];
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, path, 0, "PNG write failed: %s",
                      sink.failed ? drift__write_errno_text(sink.error, why, sizeof(why))
                                  : "encoder failed");
            r = DRIFT_ERR_IO;
        }
        r = drift__image_temp_close(ctx, &temp, r);
    }
    drift_free(ctx, rgb);
    return r;
}

// --- OPENCOLORIO (image_ocio.cpp) ---

bool drift_ocio_available(void)
{
#ifdef DRIFT_HAVE_OCIO
    return true;
#else
    return false;
#endif
}

const char *drift_ocio_default_config(void)
{
    const char *env = getenv("OCIO");
    if (env && *env) {
        return env;
    }
    static const char *const blender[] = {
        "/usr/share/blender/datafiles/colormanagement/config.ocio", // Debian's blender-data
        "/usr/share/blender/3.4/datafiles/colormanagement/config.ocio",
        "/usr/share/blender/3.6/datafiles/colormanagement/config.ocio",
        "/usr/share/blender/4.0/datafiles/colormanagement/config.ocio",
    };
    for (size_t i = 0; i < sizeof blender / sizeof blender[0]; ++i) {
        if (access(blender[i], R_OK) == 0) {
            return blender[i];
        }
    }
    return NULL;
}

drift_result drift_ocio_check_view(drift_context *ctx, const char *where,
                                   const drift_ocio_view *view)
{
    if (!view || !view->view) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
#ifndef DRIFT_HAVE_OCIO
    drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_UNSUPPORTED, where, 0,
              "this drift was built without OpenColorIO (libopencolorio-dev)");
    return DRIFT_ERR_UNSUPPORTED;
#else
    const char *config = view->config ? view->config : drift_ocio_default_config();
    char why[512] = "";
    if (!config || drift__ocio_apply(config, view->display, view->view, view->look, NULL, 0, why,
                                     sizeof why) != 0) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, where, 0, "OpenColorIO: %s",
                  config ? why : "no config (name one, set $OCIO or install blender-data)");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    return DRIFT_OK;
#endif
}

drift_result drift_image_save_png_view(drift_context *ctx, const char *path,
                                       const drift_image *image, const drift_ocio_view *view)
{
    if (!path || !view || !view->view || !drift_image_is_valid(image)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
#ifndef DRIFT_HAVE_OCIO
    drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_UNSUPPORTED, path, 0,
              "this drift was built without OpenColorIO (libopencolorio-dev): no view '%s'",
              view->view);
    return DRIFT_ERR_UNSUPPORTED;
#else
    const char *config = view->config ? view->config : drift_ocio_default_config();
    if (!config) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_UNSUPPORTED, path, 0,
                  "no OpenColorIO config: name one, set $OCIO or install Blender's "
                  "(blender-data)");
        return DRIFT_ERR_UNSUPPORTED;
    }
    size_t count = (size_t)image->width * (size_t)image->height, bytes;
    if (!drift_size_mul(count, 3 * sizeof(float), &bytes)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    float *rgb = drift_alloc(ctx, bytes);
    drift_image display = { 0 };
    drift_result r = rgb ? drift_image_create(ctx, image->width, image->height, 3, &display)
                         : DRIFT_ERR_OUT_OF_MEMORY;
    if (r != DRIFT_OK) {
        drift_free(ctx, rgb);
        return r;
    }
    float scale = exp2f(view->exposure_stops);
    for (int32_t y = 0; y < image->height; ++y) {
        for (int32_t x = 0; x < image->width; ++x) {
            const float *p = drift_image_pixel(image, x, y);
            float *q = rgb + 3 * ((size_t)y * (size_t)image->width + (size_t)x);
            for (int c = 0; c < 3; ++c) {
                q[c] = scale * p[image->channels >= 3 ? c : 0];
            }
        }
    }
    char why[512] = "";
    if (drift__ocio_apply(config, view->display, view->view, view->look, rgb, count, why,
                          sizeof why) != 0) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, path, 0, "OpenColorIO: %s",
                  why);
        r = DRIFT_ERR_INVALID_ARGUMENT;
    }
    // The view's output is display-encoded: decoded here, drift_image_save_png's own sRGB
    // encoding (exposure 0, clamp) gives the same values back, quantized to 8 bits.
    for (size_t i = 0; r == DRIFT_OK && i < count; ++i) {
        float *q = drift_image_pixel(&display, (int32_t)(i % (size_t)image->width),
                                     (int32_t)(i / (size_t)image->width));
        for (int c = 0; c < 3; ++c) {
            float v = rgb[3 * i + (size_t)c];
            q[c] = drift_srgb_to_linear(isfinite(v) ? fminf(fmaxf(v, 0.0f), 1.0f) : 0.0f);
        }
    }
    if (r == DRIFT_OK) {
        const drift_tonemap_params identity = { .exposure_stops = 0.0f, .op = DRIFT_TONEMAP_CLAMP };
        r = drift_image_save_png(ctx, path, &display, &identity);
    }
    drift_image_destroy(ctx, &display);
    drift_free(ctx, rgb);
    return r;
#endif
}

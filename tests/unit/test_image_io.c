#include "drift/image.h"
#include "drift/image_io.h"
#include "drift/math.h"
#include "drift_test.h"

#include <OpenEXR/openexr.h>
#include <dirent.h>
#include <math.h>
#include <stb/stb_image_write.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static drift_image make_random(drift_context *ctx, int32_t w, int32_t h, int32_t channels,
                               uint32_t seed, float lo, float hi)
{
    drift_image img;
    assert_int_equal(drift_image_create(ctx, w, h, channels, &img), DRIFT_OK);
    for (int32_t i = 0; i < w * h * channels; ++i) {
        img.pixels[i] = lo + (hi - lo) * test_hash_unit(seed * 7919u + (uint32_t)i);
    }
    return img;
}

static void write_bytes(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, size, f), size);
    fclose(f);
}

static uint8_t *read_bytes(const char *path, size_t *out_size)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *data = malloc((size_t)n + 1);
    assert_non_null(data);
    assert_int_equal(fread(data, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    *out_size = (size_t)n;
    return data;
}

static bool file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

// Number of entries in a directory other than . and ..
static int dir_entry_count(const char *path)
{
    DIR *d = opendir(path);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e = readdir(d); e; e = readdir(d)) {
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) {
            ++n;
        }
    }
    closedir(d);
    return n;
}

static void assert_rgb_equal_exact(const drift_image *a, const drift_image *b)
{
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    for (int32_t y = 0; y < a->height; ++y) {
        for (int32_t x = 0; x < a->width; ++x) {
            for (int c = 0; c < 3; ++c) {
                float va = drift_image_pixel(a, x, y)[a->channels >= 3 ? c : 0];
                float vb = drift_image_pixel(b, x, y)[b->channels >= 3 ? c : 0];
                assert_memory_equal(&va, &vb, sizeof(float));
            }
        }
    }
}

// Channel names of part 0 of an EXR file, comma-separated, via OpenEXRCore directly.
static void exr_channel_names(const char *path, char *out, size_t cap)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t f = NULL;
    assert_int_equal(exr_start_read(&f, path, &init), EXR_ERR_SUCCESS);
    const exr_attr_chlist_t *list = NULL;
    assert_int_equal(exr_get_channels(f, 0, &list), EXR_ERR_SUCCESS);
    out[0] = '\0';
    for (int i = 0; i < list->num_channels; ++i) {
        size_t len = strlen(out);
        snprintf(out + len, cap - len, "%s%s", i ? "," : "", list->entries[i].name.str);
    }
    exr_compression_t comp;
    assert_int_equal(exr_get_compression(f, 0, &comp), EXR_ERR_SUCCESS);
    assert_int_equal(comp, EXR_COMPRESSION_ZIP);
    exr_finish(&f);
}

static void test_image_io_exr_multilayer_round_trip_is_exact(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    // Odd sizes (more than one 16-line ZIP chunk), HDR, negative and tiny values.
    drift_image beauty = make_random(ctx, 37, 41, 3, 1, -2.0f, 1000.0f);
    beauty.pixels[5] = 1e-30f;
    beauty.pixels[6] = -0.0f;
    drift_image albedo = make_random(ctx, 37, 41, 3, 2, 0.0f, 1.0f);
    drift_image depth = make_random(ctx, 37, 41, 1, 3, 0.0f, 1e6f);
    drift_image rgba = make_random(ctx, 37, 41, 4, 4, 0.0f, 1.0f);
    drift_image_layer layers[] = {
        { "albedo", &albedo }, { NULL, &beauty }, { "depth", &depth }, { "rgba", &rgba }
    };
    char path[1024];
    test_out_path(path, "io_multilayer.exr");
    assert_int_equal(drift_image_save_exr(ctx, path, layers, 4), DRIFT_OK);

    char names[512];
    exr_channel_names(path, names, sizeof(names));
    assert_string_equal(names, "B,G,R,albedo.B,albedo.G,albedo.R,depth.Y,rgba.A,rgba.B,rgba.G,"
                               "rgba.R");

    drift_image loaded;
    assert_int_equal(drift_image_load(ctx, path, &loaded), DRIFT_OK);
    assert_int_equal(loaded.channels, 3);
    assert_rgb_equal_exact(&beauty, &loaded);
    drift_image_destroy(ctx, &loaded);

    // Without a default layer the first named RGB layer (alphabetic) is loaded.
    drift_image_layer named[] = { { "zeta", &beauty }, { "albedo", &albedo } };
    assert_int_equal(drift_image_save_exr(ctx, path, named, 2), DRIFT_OK);
    assert_int_equal(drift_image_load(ctx, path, &loaded), DRIFT_OK);
    assert_rgb_equal_exact(&albedo, &loaded);
    drift_image_destroy(ctx, &loaded);

    // A single Y channel loads as grey RGB; a strided view saves what the view shows.
    drift_image_layer grey[] = { { "", &depth } };
    assert_int_equal(drift_image_save_exr(ctx, path, grey, 1), DRIFT_OK);
    assert_int_equal(drift_image_load(ctx, path, &loaded), DRIFT_OK);
    assert_rgb_equal_exact(&depth, &loaded);
    drift_image_destroy(ctx, &loaded);
    drift_image view = drift_image_view(&beauty, 3, 5, 20, 17);
    drift_image_layer views[] = { { NULL, &view } };
    assert_int_equal(drift_image_save_exr(ctx, path, views, 1), DRIFT_OK);
    assert_int_equal(drift_image_load(ctx, path, &loaded), DRIFT_OK);
    assert_rgb_equal_exact(&view, &loaded);
    drift_image_destroy(ctx, &loaded);

    drift_image_destroy(ctx, &beauty);
    drift_image_destroy(ctx, &albedo);
    drift_image_destroy(ctx, &depth);
    drift_image_destroy(ctx, &rgba);
    drift_context_destroy(ctx);
}

// Encodes `img` into part `part` as 8x8 tiles; channels R, G, B take their component, any
// other channel (a depth Z) takes B.
static void encode_tiles(exr_context_t f, int part, const drift_image *img)
{
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    bool first = true;
    for (int ty = 0; ty * 8 < img->height; ++ty) {
        for (int tx = 0; tx * 8 < img->width; ++tx) {
            exr_chunk_info_t cinfo;
            assert_int_equal(exr_write_tile_chunk_info(f, part, tx, ty, 0, 0, &cinfo),
                             EXR_ERR_SUCCESS);
            assert_int_equal(first ? exr_encoding_initialize(f, part, &cinfo, &enc)
                                   : exr_encoding_update(f, part, &cinfo, &enc),
                             EXR_ERR_SUCCESS);
            for (int c = 0; c < enc.channel_count; ++c) {
                int k = enc.channels[c].channel_name[0] == 'R'   ? 0
                        : enc.channels[c].channel_name[0] == 'G' ? 1
                                                                 : 2;
                enc.channels[c].encode_from_ptr =
                    (const uint8_t *)(drift_image_pixel(img, tx * 8, ty * 8) + k);
                enc.channels[c].user_pixel_stride = (int32_t)(3 * sizeof(float));
                enc.channels[c].user_line_stride = (int32_t)((size_t)img->stride * sizeof(float));
                enc.channels[c].user_data_type = EXR_PIXEL_FLOAT;
                enc.channels[c].user_bytes_per_element = 4;
            }
            if (first) {
                assert_int_equal(exr_encoding_choose_default_routines(f, part, &enc),
                                 EXR_ERR_SUCCESS);
            }
            assert_int_equal(exr_encoding_run(f, part, &enc), EXR_ERR_SUCCESS);
            first = false;
        }
    }
    exr_encoding_destroy(f, &enc);
}

// Writes `img` (3 channels) as a tiled OpenEXR file (8x8 tiles, float) with OpenEXRCore.
// With `depth_first`, the file is multi-part and its first part holds only a Z channel, so a
// reader must find the colour in part 1.
static void write_tiled_exr(const char *path, const drift_image *img, exr_compression_t compression,
                            bool depth_first)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t f = NULL;
    assert_int_equal(exr_start_write(&f, path, EXR_WRITE_FILE_DIRECTLY, &init), EXR_ERR_SUCCESS);
    int parts[2] = { 0, 0 };
    int part_count = depth_first ? 2 : 1;
    for (int p = 0; p < part_count; ++p) {
        bool depth = depth_first && p == 0;
        assert_int_equal(exr_add_part(f, depth ? "depth" : "beauty", EXR_STORAGE_TILED, &parts[p]),
                         EXR_ERR_SUCCESS);
        assert_int_equal(
            exr_initialize_required_attr_simple(f, parts[p], img->width, img->height, compression),
            EXR_ERR_SUCCESS);
        assert_int_equal(
            exr_set_tile_descriptor(f, parts[p], 8, 8, EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN),
            EXR_ERR_SUCCESS);
        const char *names[3] = { "B", "G", "R" };
        for (int c = 0; c < (depth ? 1 : 3); ++c) {
            assert_int_equal(exr_add_channel(f, parts[p], depth ? "Z" : names[c], EXR_PIXEL_FLOAT,
                                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1),
                             EXR_ERR_SUCCESS);
        }
    }
    assert_int_equal(exr_write_header(f), EXR_ERR_SUCCESS);
    for (int p = 0; p < part_count; ++p) {
        encode_tiles(f, parts[p], img);
    }
    assert_int_equal(exr_finish(&f), EXR_ERR_SUCCESS);
}

static void test_image_io_tiled_exr_loads(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    // 21x13: partial tiles on the right and bottom.
    drift_image img = make_random(ctx, 21, 13, 3, 21, 0.0f, 8.0f);
    char path[1024];
    test_out_path(path, "io_tiled.exr");
    write_tiled_exr(path, &img, EXR_COMPRESSION_ZIP, false);
    drift_image loaded;
    assert_int_equal(drift_image_load(ctx, path, &loaded), DRIFT_OK);
    assert_rgb_equal_exact(&img, &loaded);
    drift_image_destroy(ctx, &loaded);
    drift_image_destroy(ctx, &img);
    drift_context_destroy(ctx);
}

// PIZ (lossless for float) and multi-part: the colour sits in part 1, behind a depth part.
static void test_image_io_piz_multipart_exr_loads(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_image img = make_random(ctx, 19, 11, 3, 23, 0.0f, 64.0f);
    char path[1024];
    test_out_path(path, "io_piz_multipart.exr");
    write_tiled_exr(path, &img, EXR_COMPRESSION_PIZ, true);
    drift_image loaded;
    assert_int_equal(drift_image_load(ctx, path, &loaded), DRIFT_OK);
    assert_rgb_equal_exact(&img, &loaded);
    drift_image_destroy(ctx, &loaded);
    drift_image_destroy(ctx, &img);
    drift_context_destroy(ctx);
}

// Components of a and b (same size) whose values differ; NaN equals NaN, and -0 equals +0
// (DWA's decoder and the ZIP re-encoding disagree on the sign of 18 zeros of city.exr).
static size_t rgb_value_differences(const drift_image *a, const drift_image *b)
{
    size_t count = 0;
    for (int32_t y = 0; y < a->height; ++y) {
        for (int32_t x = 0; x < a->width; ++x) {
            for (int c = 0; c < 3; ++c) {
                float va = drift_image_pixel(a, x, y)[c], vb = drift_image_pixel(b, x, y)[c];
                count += !(va == vb || (isnan(va) && isnan(vb)));
            }
        }
    }
    return count;
}

// Every DWAB panorama of ../shared/scenes/hdri/dwab (as Blender ships them) decodes to exactly
// the pixel values of its ZIP re-encoding one folder up. OpenEXRCore 3.1 cannot decode DWAB; the
// C++ shim (src/io/image_exr_dwa.cpp) does.
static void test_image_io_dwab_panoramas_equal_zip_copies(void **state)
{
    (void)state;
    char dir[1024];
    struct stat st;
    if (stat(test_shared_path(dir, "scenes/hdri/dwab"), &st) != 0) {
        fprintf(stderr, "skipped: %s is absent\n", dir);
        skip();
    }
    static const char *const names[] = { "city",  "courtyard", "forest",  "interior",
                                         "night", "studio",    "sunrise", "sunset" };
    drift_context *ctx = test_context(1, NULL);
    for (size_t i = 0; i < sizeof(names) / sizeof(names[0]); ++i) {
        char dwab_rel[256], zip_rel[256], dwab_path[1024], zip_path[1024];
        snprintf(dwab_rel, sizeof(dwab_rel), "scenes/hdri/dwab/%s.exr", names[i]);
        snprintf(zip_rel, sizeof(zip_rel), "scenes/hdri/%s.exr", names[i]);
        drift_image dwab, zip;
        assert_int_equal(drift_image_load(ctx, test_shared_path(dwab_path, dwab_rel), &dwab),
                         DRIFT_OK);
        assert_int_equal(drift_image_load(ctx, test_shared_path(zip_path, zip_rel), &zip),
                         DRIFT_OK);
        assert_int_equal(dwab.width, 1024);
        assert_int_equal(dwab.height, 512);
        assert_int_equal(zip.width, 1024);
        assert_int_equal(zip.height, 512);
        size_t differences = rgb_value_differences(&dwab, &zip);
        if (differences != 0) {
            fprintf(stderr, "%s: %zu DWAB components differ from the ZIP copy\n", names[i],
                    differences);
        }
        assert_int_equal(differences, 0);
        drift_image_destroy(ctx, &dwab);
        drift_image_destroy(ctx, &zip);
    }
    drift_context_destroy(ctx);
}

// Writes `img` (1 to 4 channels, named as drift_image_save_exr names them, so the packed
// chunks are byte for byte the ones drift's writer compresses) as a ZIP scanline OpenEXR file
// with OpenEXRCore, and returns how many chunks its ZIP compressor turned into data exactly
// as long as the raw chunk yet different from it: the data every reader takes as raw.
static int zip_chunks_at_raw_size(const char *path, const drift_image *img)
{
    static const char *const names[4][4] = {
        { "Y" }, { "Y", "A" }, { "R", "G", "B" }, { "R", "G", "B", "A" }
    };
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t f = NULL;
    int part = 0;
    assert_int_equal(exr_start_write(&f, path, EXR_WRITE_FILE_DIRECTLY, &init), EXR_ERR_SUCCESS);
    assert_int_equal(exr_add_part(f, NULL, EXR_STORAGE_SCANLINE, &part), EXR_ERR_SUCCESS);
    assert_int_equal(
        exr_initialize_required_attr_simple(f, part, img->width, img->height, EXR_COMPRESSION_ZIP),
        EXR_ERR_SUCCESS);
    for (int c = 0; c < img->channels; ++c) {
        assert_int_equal(exr_add_channel(f, part, names[img->channels - 1][c], EXR_PIXEL_FLOAT,
                                         EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1),
                         EXR_ERR_SUCCESS);
    }
    assert_int_equal(exr_write_header(f), EXR_ERR_SUCCESS);
    int32_t lines = 0;
    assert_int_equal(exr_get_scanlines_per_chunk(f, part, &lines), EXR_ERR_SUCCESS);
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int hits = 0;
    for (int32_t y = 0; y < img->height; y += lines) {
        exr_chunk_info_t cinfo;
        assert_int_equal(exr_write_scanline_chunk_info(f, part, y, &cinfo), EXR_ERR_SUCCESS);
        assert_int_equal(y == 0 ? exr_encoding_initialize(f, part, &cinfo, &enc)
                                : exr_encoding_update(f, part, &cinfo, &enc),
                         EXR_ERR_SUCCESS);
        for (int c = 0; c < enc.channel_count; ++c) {
            int k = 0;
            while (strcmp(names[img->channels - 1][k], enc.channels[c].channel_name) != 0) {
                ++k;
            }
            enc.channels[c].encode_from_ptr = (const uint8_t *)(drift_image_pixel(img, 0, y) + k);
            enc.channels[c].user_pixel_stride = (int32_t)((size_t)img->channels * sizeof(float));
            enc.channels[c].user_line_stride = (int32_t)((size_t)img->stride * sizeof(float));
            enc.channels[c].user_data_type = EXR_PIXEL_FLOAT;
            enc.channels[c].user_bytes_per_element = 4;
        }
        if (y == 0) {
            assert_int_equal(exr_encoding_choose_default_routines(f, part, &enc), EXR_ERR_SUCCESS);
        }
        assert_int_equal(exr_encoding_run(f, part, &enc), EXR_ERR_SUCCESS);
        if (enc.compressed_bytes == enc.packed_bytes &&
            enc.compressed_buffer != enc.packed_buffer &&
            memcmp(enc.compressed_buffer, enc.packed_buffer, enc.packed_bytes) != 0) {
            ++hits;
        }
    }
    exr_encoding_destroy(f, &enc);
    exr_finish(&f);
    return hits;
}

// OpenEXR 3.1.5's ZIP encoder keeps its output when it is exactly as long as the raw chunk,
// but a chunk whose size equals the uncompressed size is raw to every reader. Rows 16-31 here
// are k random floats and then a constant; somewhere near k = all, deflate's output crosses
// the raw size, and for some seed it lands on it exactly. drift must store that chunk raw.
// Auto exposure brings the geometric mean of the lit pixels to 0.18 and ignores unlit ones;
// EV100 follows its closed forms (sunny 16: f/16, 1/100 s, ISO 100 is EV100 14.64); the
// filmic curve is Narkowicz's ACES fit, monotonic, 0 at 0 and white far above 1.
static void test_image_io_exposure_and_filmic(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_image img;
    assert_int_equal(drift_image_create(ctx, 4, 2, 3, &img), DRIFT_OK);
    // Row 0 grey 0.5 and 8 (geometric mean 2), row 1 black.
    for (int32_t x = 0; x < 4; ++x) {
        float v = x % 2 ? 8.0f : 0.5f;
        for (int c = 0; c < 3; ++c) {
            drift_image_pixel(&img, x, 0)[c] = v;
        }
    }
    float expected = (float)(log2(0.18) - 0.5 * (log2(0.5 + 1e-4) + log2(8.0 + 1e-4)));
    assert_float_equal(drift_image_auto_exposure(&img), expected, 1e-5f);
    drift_image_pixel(&img, 0, 1)[1] = NAN; // not finite: ignored too
    assert_float_equal(drift_image_auto_exposure(&img), expected, 1e-5f);
    drift_image_destroy(ctx, &img);
    assert_int_equal(drift_image_create(ctx, 2, 2, 3, &img), DRIFT_OK);
    assert_float_equal(drift_image_auto_exposure(&img), 0.0f, 0.0f); // no light
    drift_image_destroy(ctx, &img);

    assert_float_equal(drift_ev100_from_camera(16.0f, 0.01f, 100.0f), log2f(25600.0f), 1e-4f);
    assert_float_equal(drift_ev100_from_camera(16.0f, 0.01f, 200.0f), log2f(12800.0f), 1e-4f);
    // A radiance of 1.2 · 2^EV100 / 683 W/(m² sr) (1.2 · 2^EV100 cd/m²) just saturates.
    float ev = 9.0f;
    float saturating = 1.2f * exp2f(ev) / 683.0f;
    assert_float_equal(saturating * exp2f(drift_exposure_from_ev100(ev)), 1.0f, 1e-5f);

    drift_tonemap_params filmic = { .op = DRIFT_TONEMAP_FILMIC };
    assert_float_equal(drift_tonemap_value(0.0f, &filmic), 0.0f, 0.0f);
    float x = 0.18f;
    float aces = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
    assert_float_equal(drift_tonemap_value(x, &filmic), drift_linear_to_srgb(aces), 1e-6f);
    assert_float_equal(drift_tonemap_value(100.0f, &filmic), 1.0f, 0.0f);
    float last = 0.0f;
    for (int i = 1; i <= 200; ++i) {
        float v = drift_tonemap_value(0.05f * (float)i, &filmic);
        assert_true(v >= last);
        last = v;
    }
    drift_context_destroy(ctx);
}

static void test_image_io_exr_chunk_compressing_to_raw_size_round_trips(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    char path[1024], probe[1024];
    test_out_path(path, "io_raw_size.exr");
    test_out_path(probe, "io_raw_size_probe.exr");
    const int32_t w = 16, h = 32;
    const int32_t n = w * 16 * 3; // floats in the second chunk
    drift_image img;
    assert_int_equal(drift_image_create(ctx, w, h, 3, &img), DRIFT_OK);
    bool found = false;
    for (uint32_t seed = 0; seed < 64 && !found; ++seed) {
        for (int32_t k = n - 48; k <= n && !found; ++k) {
            for (int32_t i = 0; i < w * h * 3; ++i) {
                int32_t j = i - w * 16 * 3;
                img.pixels[i] = j < 0   ? 0.25f
                                : j < k ? test_hash_unit(seed * 100003u + (uint32_t)j)
                                        : 0.5f;
            }
            found = zip_chunks_at_raw_size(probe, &img) > 0;
        }
    }
    assert_true(found); // else this zlib never lands on the raw size and the test proves nothing
    drift_image_layer layers[] = { { NULL, &img } };
    assert_int_equal(drift_image_save_exr(ctx, path, layers, 1), DRIFT_OK);
    drift_image loaded;
    assert_int_equal(drift_image_load(ctx, path, &loaded), DRIFT_OK);
    assert_rgb_equal_exact(&img, &loaded);
    drift_image_destroy(ctx, &loaded);
    drift_image_destroy(ctx, &img);
    drift_context_destroy(ctx);
}

// Round trips of random images: sizes from 1x1 to over three chunks, 1 to 4 channels, rows
// from constant to incompressible (so some chunks land near their raw size), signed zeros,
// denormals and huge values; every value comes back bit for bit.
static void test_image_io_exr_random_round_trips_are_exact(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    char path[1024];
    test_out_path(path, "io_random.exr");
    static const float specials[] = { -0.0f, 0.0f, 1e-40f, -1e-40f, 3e38f, -3e38f, 1.0f, 65504.0f };
    for (uint32_t trial = 0; trial < 40; ++trial) {
        uint32_t s = trial * 1013u;
        int32_t w = 1 + (int32_t)(test_hash_unit(s + 1) * 70.0f);
        int32_t h = 1 + (int32_t)(test_hash_unit(s + 2) * 56.0f);
        int32_t channels = 1 + (int32_t)(test_hash_unit(s + 3) * 4.0f);
        drift_image img;
        assert_int_equal(drift_image_create(ctx, w, h, channels, &img), DRIFT_OK);
        for (int32_t y = 0; y < h; ++y) {
            // Per row: the share of random values, and whether they are coarse or full floats.
            float random_share = test_hash_unit(s * 31u + (uint32_t)y * 7u + 4);
            bool coarse = test_hash_unit(s * 31u + (uint32_t)y * 7u + 5) < 0.3f;
            for (int32_t x = 0; x < w * channels; ++x) {
                uint32_t i = s * 65537u + (uint32_t)(y * w * channels + x);
                float u = test_hash_unit(i * 3u + 1);
                float v = test_hash_unit(i * 3u + 2);
                float value = 0.5f;
                if (u < 0.02f) {
                    value = specials[(int)(v * 8.0f) & 7];
                } else if (u < random_share) {
                    value = coarse ? floorf(v * 8.0f) / 8.0f : (v - 0.3f) * 1000.0f;
                }
                drift_image_pixel(&img, 0, y)[x] = value;
            }
        }
        drift_image_layer layers[] = { { NULL, &img } };
        assert_int_equal(drift_image_save_exr(ctx, path, layers, 1), DRIFT_OK);
        drift_image loaded;
        assert_int_equal(drift_image_load(ctx, path, &loaded), DRIFT_OK);
        assert_rgb_equal_exact(&img, &loaded);
        if (channels == 4) {
            assert_int_equal(loaded.channels, 3);
        }
        drift_image_destroy(ctx, &loaded);
        drift_image_destroy(ctx, &img);
    }
    drift_context_destroy(ctx);
}

static void test_image_io_png_round_trip_within_quantization(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_image img = make_random(ctx, 23, 19, 3, 9, 0.0f, 1.0f);
    char path[1024];
    test_out_path(path, "io_round_trip.PNG"); // extension match is case-insensitive
    assert_int_equal(drift_image_save_png(ctx, path, &img, NULL), DRIFT_OK);
    drift_image loaded;
    assert_int_equal(drift_image_load(ctx, path, &loaded), DRIFT_OK);
    assert_int_equal(loaded.width, 23);
    assert_int_equal(loaded.height, 19);
    assert_int_equal(loaded.channels, 3);
    // 8-bit quantisation happens in sRGB space: half a code value there.
    for (int32_t i = 0; i < 23 * 19 * 3; ++i) {
        float a = drift_linear_to_srgb(img.pixels[i]);
        float b = drift_linear_to_srgb(loaded.pixels[i]);
        assert_near(a, b, 0.5 / 255.0 + 1e-4);
    }
    drift_image_destroy(ctx, &loaded);
    drift_image_destroy(ctx, &img);
    drift_context_destroy(ctx);
}

static void test_image_io_png16_jpeg_and_hdr_load(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    char path[1024];
    drift_image loaded;

    // Radiance HDR: linear floats with RGBE precision (8-bit mantissa per pixel).
    float hdr[4 * 3 * 3];
    for (int i = 0; i < 36; ++i) {
        hdr[i] = 0.1f + 10.0f * test_hash_unit((uint32_t)i);
    }
    test_out_path(path, "io_load.hdr");
    assert_true(stbi_write_hdr(path, 4, 3, 3, hdr) != 0);
    assert_int_equal(drift_image_load(ctx, path, &loaded), DRIFT_OK);
    for (int i = 0; i < 36; ++i) {
        assert_near(loaded.pixels[i], hdr[i], 0.01 * 11.0);
    }
    drift_image_destroy(ctx, &loaded);

    // JPEG: 8-bit sRGB, lossy; a flat grey survives closely.
    uint8_t grey[8 * 8 * 3];
    memset(grey, 128, sizeof(grey));
    test_out_path(path, "io_load.jpeg");
    assert_true(stbi_write_jpg(path, 8, 8, 3, grey, 100) != 0);
    assert_int_equal(drift_image_load(ctx, path, &loaded), DRIFT_OK);
    assert_near(loaded.pixels[0], drift_srgb_to_linear(128.0f / 255.0f), 0.01);
    drift_image_destroy(ctx, &loaded);

    // 16-bit grey PNG, written by hand: signature, IHDR, one stored-deflate IDAT, IEND.
    // (stb cannot write 16-bit; a stored zlib block needs no compressor.) stb does not check
    // chunk CRCs or the Adler-32, so those are left zero.
    static const uint8_t png16[] = {
        0x89, 'P',  'N',  'G', '\r', '\n', 0x1a, '\n', 0,   0,   0,   13,   'I',  'H',  'D',
        'R',  0,    0,    0,   2,    0,    0,    0,    1,   16,  0,   0,    0,    0,    0,
        0,    0,    0,    0,   0,    0,    16,   'I',  'D', 'A', 'T', 0x78, 0x01, 0x01, 5,
        0,    0xfa, 0xff, 0,   0xff, 0xff, 0x80, 0x00, 0,   0,   0,   0,    0,    0,    0,
        0,    0,    0,    0,   0,    'I',  'E',  'N',  'D', 0,   0,   0,    0,
    };
    test_out_path(path, "io_load16.png");
    write_bytes(path, png16, sizeof(png16));
    drift_result r = drift_image_load(ctx, path, &loaded);
    assert_int_equal(r, DRIFT_OK);
    assert_int_equal(loaded.width, 2);
    assert_near(loaded.pixels[0], 1.0, 1e-6);
    assert_near(loaded.pixels[3], drift_srgb_to_linear(32768.0f / 65535.0f), 1e-6);
    drift_image_destroy(ctx, &loaded);
    drift_context_destroy(ctx);
}

static void test_image_io_errors_have_codes(void **state)
{
    (void)state;
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(1, &cap);
    drift_image img = { .width = 5 };
    char path[1024];

    assert_int_equal(drift_image_load(ctx, "/nonexistent/dir/file.exr", &img), DRIFT_ERR_IO);
    assert_int_equal(cap.last_code, DRIFT_ERR_IO);
    assert_non_null(strstr(cap.last_message, "cannot open"));
    assert_null(img.pixels);
    assert_int_equal(img.width, 0);

    assert_int_equal(drift_image_load(ctx, "picture.tiff", &img), DRIFT_ERR_UNSUPPORTED);
    assert_int_equal(drift_image_load(ctx, "no_extension", &img), DRIFT_ERR_UNSUPPORTED);
    assert_int_equal(cap.last_code, DRIFT_ERR_UNSUPPORTED);

    // A PNG header claiming 40000 x 1 pixels is refused before any pixel allocation.
    static const uint8_t huge[] = {
        0x89, 'P',  'N',  'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R', 0,
        0,    0x9c, 0x40, 0,   0,    0,    1,    8,    2, 0, 0, 0,  0,   0,   0,   0,
    };
    test_out_path(path, "io_huge.png");
    write_bytes(path, huge, sizeof(huge));
    assert_int_equal(drift_image_load(ctx, path, &img), DRIFT_ERR_INVALID_ARGUMENT);

    // PNG content behind an .hdr name does not silently decode with a guessed gamma.
    drift_image small = make_random(ctx, 4, 4, 3, 1, 0.0f, 1.0f);
    test_out_path(path, "io_mismatch.png");
    assert_int_equal(drift_image_save_png(ctx, path, &small, NULL), DRIFT_OK);
    char renamed[1024];
    test_out_path(renamed, "io_mismatch.hdr");
    assert_int_equal(rename(path, renamed), 0);
    assert_int_equal(drift_image_load(ctx, renamed, &img), DRIFT_ERR_PARSE);
    drift_image_destroy(ctx, &small);
    drift_context_destroy(ctx);
}

// Every prefix of a valid file, and a few byte flips, must fail cleanly (or, for flips that
// hit pixel data, load) — never crash. ASan/UBSan watch the decoders.
static void check_damaged_copies(drift_context *ctx, test_log_capture *cap, const char *good,
                                 const char *bad)
{
    size_t size = 0;
    uint8_t *data = read_bytes(good, &size);
    size_t step = size / 97 + 1;
    for (size_t len = 0; len < size; len += step) {
        write_bytes(bad, data, len);
        drift_image img;
        cap->last_code = DRIFT_OK;
        drift_result r = drift_image_load(ctx, bad, &img);
        assert_int_equal(r, DRIFT_ERR_PARSE);
        assert_int_equal(cap->last_code, DRIFT_ERR_PARSE);
        assert_null(img.pixels);
    }
    // Dropping only the last byte is a truncated file too.
    write_bytes(bad, data, size - 1);
    drift_image img;
    assert_int_equal(drift_image_load(ctx, bad, &img), DRIFT_ERR_PARSE);
    for (uint32_t i = 0; i < 64; ++i) {
        size_t at = drift_hash_u32(i) % size;
        data[at] ^= (uint8_t)(1u + drift_hash_u32(i + 100) % 255u);
        write_bytes(bad, data, size);
        drift_result r = drift_image_load(ctx, bad, &img);
        assert_true(r == DRIFT_OK || r == DRIFT_ERR_PARSE || r == DRIFT_ERR_UNSUPPORTED ||
                    r == DRIFT_ERR_INVALID_ARGUMENT);
        drift_image_destroy(ctx, &img);
        data[at] ^= (uint8_t)(1u + drift_hash_u32(i + 100) % 255u);
    }
    free(data);
}

static void test_image_io_truncated_and_corrupt_files_fail_cleanly(void **state)
{
    (void)state;
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(1, &cap);
    drift_image img = make_random(ctx, 40, 35, 3, 5, 0.0f, 4.0f);
    char good[1024], bad[1024];

    test_out_path(good, "io_good.exr");
    drift_image_layer layers[] = { { NULL, &img }, { "extra", &img } };
    assert_int_equal(drift_image_save_exr(ctx, good, layers, 2), DRIFT_OK);
    test_out_path(bad, "io_bad.exr");
    check_damaged_copies(ctx, &cap, good, bad);

    test_out_path(good, "io_good.png");
    assert_int_equal(drift_image_save_png(ctx, good, &img, NULL), DRIFT_OK);
    test_out_path(bad, "io_bad.png");
    check_damaged_copies(ctx, &cap, good, bad);

    // Garbage with the right extension.
    const char garbage[] = "this is not an image at all, just some text";
    write_bytes(bad, garbage, sizeof(garbage));
    drift_image out;
    assert_int_equal(drift_image_load(ctx, bad, &out), DRIFT_ERR_PARSE);
    test_out_path(bad, "io_bad.exr");
    write_bytes(bad, garbage, sizeof(garbage));
    assert_int_equal(drift_image_load(ctx, bad, &out), DRIFT_ERR_PARSE);
    drift_image_destroy(ctx, &img);
    drift_context_destroy(ctx);
}

static void test_image_io_writers_leave_no_file_on_failure(void **state)
{
    (void)state;
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(1, &cap);
    drift_image img = make_random(ctx, 8, 8, 3, 1, 0.0f, 1.0f);
    drift_image other = make_random(ctx, 9, 8, 3, 1, 0.0f, 1.0f);
    char dir[1024], path[2048];
    test_out_path(dir, "io_writer_dir");
    mkdir(dir, 0755);
    // Start from an empty directory.
    DIR *d = opendir(dir);
    for (struct dirent *e = readdir(d); e; e = readdir(d)) {
        if (e->d_name[0] != '.') {
            snprintf(path, sizeof(path), "%s/%s", dir, e->d_name);
            rmdir(path);
            unlink(path);
        }
    }
    closedir(d);
    drift_image_layer layers[] = { { NULL, &img } };

    // A missing directory.
    snprintf(path, sizeof(path), "%s/missing/out.exr", dir);
    assert_int_equal(drift_image_save_exr(ctx, path, layers, 1), DRIFT_ERR_IO);
    assert_int_equal(cap.last_code, DRIFT_ERR_IO);
    snprintf(path, sizeof(path), "%s/missing/out.png", dir);
    assert_int_equal(drift_image_save_png(ctx, path, &img, NULL), DRIFT_ERR_IO);
    assert_int_equal(dir_entry_count(dir), 0);

    // The target is a directory: everything is written, the final rename fails, and the
    // temporary file must be gone.
    snprintf(path, sizeof(path), "%s/target", dir);
    assert_int_equal(mkdir(path, 0755), 0);
    assert_int_equal(drift_image_save_exr(ctx, path, layers, 1), DRIFT_ERR_IO);
    assert_int_equal(drift_image_save_png(ctx, path, &img, NULL), DRIFT_ERR_IO);
    assert_int_equal(dir_entry_count(dir), 1);
    assert_int_equal(dir_entry_count(path), 0);
    rmdir(path);

    // Invalid layers fail before any file is created.
    drift_image_layer mismatch[] = { { NULL, &img }, { "b", &other } };
    drift_image_layer duplicate[] = { { "a", &img }, { "a", &img } };
    snprintf(path, sizeof(path), "%s/layers.exr", dir);
    assert_int_equal(drift_image_save_exr(ctx, path, mismatch, 2), DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_image_save_exr(ctx, path, duplicate, 2), DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_image_save_exr(ctx, path, layers, 0), DRIFT_ERR_INVALID_ARGUMENT);
    assert_false(file_exists(path));

    // An unwritable directory (not meaningful as root, who may write anyway).
    if (geteuid() != 0) {
        chmod(dir, 0555);
        snprintf(path, sizeof(path), "%s/ro.exr", dir);
        assert_int_equal(drift_image_save_exr(ctx, path, layers, 1), DRIFT_ERR_IO);
        chmod(dir, 0755);
    }
    assert_int_equal(dir_entry_count(dir), 0);

    // And success replaces an existing file atomically, leaving only the target.
    snprintf(path, sizeof(path), "%s/ok.png", dir);
    assert_int_equal(drift_image_save_png(ctx, path, &img, NULL), DRIFT_OK);
    assert_int_equal(drift_image_save_png(ctx, path, &img, NULL), DRIFT_OK);
    assert_int_equal(dir_entry_count(dir), 1);
    unlink(path);
    drift_image_destroy(ctx, &img);
    drift_image_destroy(ctx, &other);
    drift_context_destroy(ctx);
}

// Inputs the fuzzer (tests/fuzz/fuzz_image_load.c) found crashing, kept as regressions.
static void test_image_io_fuzz_regressions(void **state)
{
    (void)state;
    // EXR whose picked G channel is subsampled: the error message read the channel list after
    // the OpenEXR context had freed it (heap-use-after-free).
    static const uint8_t subsampled_exr[] = {
        0x76, 0x2f, 0x31, 0x01, 0x02, 0x00, 0x00, 0x00, 0x74, 0x79, 0x70, 0x65, 0x00, 0x73, 0x74,
        0x72, 0x69, 0x6e, 0x67, 0x00, 0x00, 0x00, 0x73, 0x63, 0x72, 0x65, 0x65, 0x6e, 0x57, 0x69,
        0x6e, 0x64, 0x6f, 0x77, 0x57, 0x69, 0x64, 0x74, 0x68, 0x00, 0x66, 0x6c, 0x6f, 0x61, 0x74,
        0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0x3f, 0x63, 0x68, 0x61, 0x6e, 0x6e, 0x65,
        0x6c, 0x73, 0x00, 0x63, 0x68, 0x6c, 0x69, 0x73, 0x74, 0x00, 0x37, 0x00, 0x00, 0x00, 0x42,
        0x00, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00,
        0x00, 0x00, 0x47, 0x00, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x10, 0x00, 0x00,
        0x00, 0x01, 0x00, 0x00, 0x00, 0x52, 0x00, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
        0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x66, 0x01, 0x00, 0x00, 0x00,
        0x00, 0x00, 0x00, 0x6e, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
        0x00, 0x0f, 0x00, 0x00, 0xf5, 0xc4, 0x75, 0x43, 0x32, 0x1a, 0xec, 0x40, 0x43, 0xac, 0x51,
        0x44, 0x7c, 0x8a, 0x4c, 0x42, 0x9a, 0xc5, 0xf3, 0x43, 0xee, 0x91, 0x7b, 0x43, 0xf5, 0x90,
        0x1c, 0x44, 0xaa, 0x7a, 0x90, 0x43, 0x20,
    };
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(1, &cap);
    char path[1024];
    test_out_path(path, "io_fuzz_subsampled.exr");
    write_bytes(path, subsampled_exr, sizeof(subsampled_exr));
    drift_image img;
    assert_int_equal(drift_image_load(ctx, path, &img), DRIFT_ERR_UNSUPPORTED);
    assert_non_null(strstr(cap.last_message, "subsampled"));

    // A 16-bit PGM ("P557 3 557", 57 x 3 pixels) behind a .png name: stb's PNM decoder
    // converted its one channel to three into too short a buffer (heap-buffer-overflow). Its
    // content is not PNG, so it is refused before any decoder runs; so it is behind .jpg and
    // .hdr names.
    static const uint8_t pgm16[] = { 0x50, 0x35, 0x35, 0x37, 0x0a, 0x33, 0x09, 0x35,
                                     0x35, 0x37, 0x0a, 0x33, 0xff, 0xff, 0x5d, 0x00,
                                     0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xff,
                                     0xff, 0xff, 0xff, 0xf7, 0xff, 0x59, 0x1c, 0x20 };
    const char *disguises[] = { "io_fuzz_pgm16.png", "io_fuzz_pgm16.jpg", "io_fuzz_pgm16.hdr" };
    for (int k = 0; k < 3; ++k) {
        test_out_path(path, disguises[k]);
        write_bytes(path, pgm16, sizeof(pgm16));
        cap.last_code = DRIFT_OK;
        assert_int_equal(drift_image_load(ctx, path, &img), DRIFT_ERR_PARSE);
        assert_non_null(strstr(cap.last_message, "does not match the extension"));
        assert_null(img.pixels);
    }
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_image_io_exr_multilayer_round_trip_is_exact),
        cmocka_unit_test(test_image_io_tiled_exr_loads),
        cmocka_unit_test(test_image_io_piz_multipart_exr_loads),
        cmocka_unit_test(test_image_io_dwab_panoramas_equal_zip_copies),
        cmocka_unit_test(test_image_io_exposure_and_filmic),
        cmocka_unit_test(test_image_io_exr_chunk_compressing_to_raw_size_round_trips),
        cmocka_unit_test(test_image_io_exr_random_round_trips_are_exact),
        cmocka_unit_test(test_image_io_png_round_trip_within_quantization),
        cmocka_unit_test(test_image_io_png16_jpeg_and_hdr_load),
        cmocka_unit_test(test_image_io_errors_have_codes),
        cmocka_unit_test(test_image_io_truncated_and_corrupt_files_fail_cleanly),
        cmocka_unit_test(test_image_io_writers_leave_no_file_on_failure),
        cmocka_unit_test(test_image_io_fuzz_regressions),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

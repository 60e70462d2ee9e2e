// What other tools see in drift's outputs (issue 42): `drift render --aov` read back with
// OpenEXR's own reader (OpenEXRCore, the library tev, Nuke and Blender build on) lists the
// conventional channel names (Z, N.X/N.Y/N.Z, albedo.R/G/B) and carries the chromaticities
// and the render's settings; the PNG beside it has a valid sRGB chunk before its pixels.
#include "drift/image.h"
#include "drift/image_io.h"
#include "drift_test.h"

#include <OpenEXR/openexr.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// Renders the built-in scene, 12x10 at 1 spp with --aov, to `exr`.
static void render_with_aovs(const char *exr)
{
    const char *bin = getenv("DRIFT_BIN");
    assert_non_null(bin);
    char command[4096];
    snprintf(command, sizeof command,
             "'%s' render --spp 1 --width 12 --height 10 --seed 7 --aov --checkpoint 0 --quiet "
             "--threads 1 --out '%s' > /dev/null",
             bin, exr);
    assert_int_equal(system(command), 0);
}

static void test_exr_conventions_channels_and_metadata(void **state)
{
    (void)state;
    char exr[1024];
    test_out_path(exr, "conventions.exr");
    render_with_aovs(exr);

    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t f = NULL;
    assert_int_equal(exr_start_read(&f, exr, &init), EXR_ERR_SUCCESS);
    const exr_attr_chlist_t *list = NULL;
    assert_int_equal(exr_get_channels(f, 0, &list), EXR_ERR_SUCCESS);
    char names[512] = "";
    for (int i = 0; i < list->num_channels; ++i) {
        size_t len = strlen(names);
        snprintf(names + len, sizeof names - len, "%s%s", i ? "," : "", list->entries[i].name.str);
    }
    // OpenEXR lists channels sorted by name.
    // The conventional layers, then the feature-guided denoiser's inputs (issue 48: the
    // features, the variances and the direct light, tools/cmd_render.c).
    assert_string_equal(names, "B,G,N.X,N.Y,N.Z,R,Z,albedo.B,albedo.G,albedo.R,"
                               "direct.B,direct.G,direct.R,direct_variance.Y,"
                               "feature_albedo.B,feature_albedo.G,feature_albedo.R,"
                               "feature_depth.Y,feature_normal.X,feature_normal.Y,"
                               "feature_normal.Z,indirect_variance.Y,variance.Y");

    exr_attr_chromaticities_t chroma_value = { 0 }, *chroma = &chroma_value;
    assert_int_equal(exr_attr_get_chromaticities(f, 0, "chromaticities", chroma), EXR_ERR_SUCCESS);
    assert_near(chroma->red_x, 0.64, 1e-6);
    assert_near(chroma->green_y, 0.60, 1e-6);
    assert_near(chroma->blue_x, 0.15, 1e-6);
    assert_near(chroma->white_x, 0.3127, 1e-6);
    assert_near(chroma->white_y, 0.3290, 1e-6);

    const char *value = NULL;
    int32_t length = 0;
    assert_int_equal(exr_attr_get_string(f, 0, "drift.spp", &length, &value), EXR_ERR_SUCCESS);
    assert_string_equal(value, "1");
    assert_int_equal(exr_attr_get_string(f, 0, "drift.seed", &length, &value), EXR_ERR_SUCCESS);
    assert_string_equal(value, "7");
    assert_int_equal(exr_attr_get_string(f, 0, "drift.max_depth", &length, &value),
                     EXR_ERR_SUCCESS);
    assert_true(atoi(value) > 0);
    assert_int_equal(exr_attr_get_string(f, 0, "drift.scene", &length, &value), EXR_ERR_SUCCESS);
    assert_non_null(strstr(value, ".json"));
    exr_finish(&f);
}

// The channel names of `exr` as OpenEXR's reader lists them (sorted), comma-separated.
static void exr_channel_names(const char *exr, char *names, size_t capacity)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t f = NULL;
    assert_int_equal(exr_start_read(&f, exr, &init), EXR_ERR_SUCCESS);
    const exr_attr_chlist_t *list = NULL;
    assert_int_equal(exr_get_channels(f, 0, &list), EXR_ERR_SUCCESS);
    names[0] = '\0';
    for (int i = 0; i < list->num_channels; ++i) {
        size_t len = strlen(names);
        snprintf(names + len, capacity - len, "%s%s,", i ? "" : ",", list->entries[i].name.str);
    }
    exr_finish(&f);
}

// The hybrid mode's --aov FILE.exr: the G-buffer's normals as N.X/N.Y/N.Z, or with
// --aov-normal Normal as Blender's Normal.X/Y/Z (and no N.*), depth as Z, either way.
static void test_exr_conventions_hybrid_aov_normal(void **state)
{
    (void)state;
    const char *bin = getenv("DRIFT_BIN");
    assert_non_null(bin);
    static const char *const layers[2] = { "N", "Normal" };
    for (int blender = 0; blender < 2; ++blender) {
        char out[1024], aov[1024], command[4096];
        test_out_path(out, blender ? "hybrid_blender.exr" : "hybrid_n.exr");
        test_out_path(aov, blender ? "hybrid_blender_aov.exr" : "hybrid_n_aov.exr");
        snprintf(command, sizeof command,
                 "'%s' render --mode hybrid --indirect none --width 12 --height 10 --threads 1 "
                 "--quiet --aov '%s' %s --out '%s' > /dev/null",
                 bin, aov, blender ? "--aov-normal Normal" : "", out);
        assert_int_equal(system(command), 0);
        char names[8192];
        exr_channel_names(aov, names, sizeof names);
        for (int l = 0; l < 2; ++l) {
            for (const char *c = "XYZ"; *c; ++c) {
                char channel[32];
                snprintf(channel, sizeof channel, ",%s.%c,", layers[l], *c);
                if ((strstr(names, channel) != NULL) != (l == blender)) {
                    fail_msg("--aov-normal %s: channel %s %s in %s", layers[blender], channel,
                             l == blender ? "missing" : "present", names);
                }
            }
        }
        assert_non_null(strstr(names, ",Z,"));
    }
}

// The PNG's CRC-32 (ISO 3309), for checking the chunk drift writes by hand.
static uint32_t crc32_of(const uint8_t *data, size_t size)
{
    uint32_t crc = 0xffffffffu;
    for (size_t i = 0; i < size; ++i) {
        crc ^= data[i];
        for (int k = 0; k < 8; ++k) {
            crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
        }
    }
    return ~crc;
}

static uint32_t be32(const uint8_t *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static void test_exr_conventions_png_has_srgb_chunk(void **state)
{
    (void)state;
    char exr[1024], png[1024];
    test_out_path(exr, "conventions_png.exr");
    test_out_path(png, "conventions_png.png");
    render_with_aovs(exr);
    FILE *file = fopen(png, "rb");
    assert_non_null(file);
    static uint8_t data[1 << 16];
    size_t size = fread(data, 1, sizeof data, file);
    fclose(file);
    assert_true(size > 8 && size < sizeof data);
    // Walk the chunks: IHDR first, sRGB (intent 0..3, valid CRC) before the first IDAT.
    bool srgb = false, idat = false;
    for (size_t at = 8; at + 12 <= size;) {
        uint32_t length = be32(data + at);
        assert_true(at + 12 + length <= size);
        const uint8_t *type = data + at + 4;
        assert_int_equal(be32(data + at + 8 + length), crc32_of(type, 4 + (size_t)length));
        if (at == 8) {
            assert_memory_equal(type, "IHDR", 4);
        }
        if (memcmp(type, "sRGB", 4) == 0) {
            assert_false(idat);
            assert_int_equal(length, 1);
            assert_true(type[4] <= 3);
            srgb = true;
        }
        idat = idat || memcmp(type, "IDAT", 4) == 0;
        at += 12 + length;
    }
    assert_true(srgb);
    assert_true(idat);
    // The image still loads, and has the size it was rendered at.
    drift_context *ctx = test_context(1, NULL);
    drift_image loaded;
    assert_int_equal(drift_image_load(ctx, png, &loaded), DRIFT_OK);
    assert_int_equal(loaded.width, 12);
    assert_int_equal(loaded.height, 10);
    drift_image_destroy(ctx, &loaded);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exr_conventions_channels_and_metadata),
        cmocka_unit_test(test_exr_conventions_png_has_srgb_chunk),
        cmocka_unit_test(test_exr_conventions_hybrid_aov_normal),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

// A program that uses libdrift: loads a scene, renders the hybrid frame (the techniques
// `drift render --mode hybrid` starts from) and the path tracer's reference, writes both
// (EXR and PNG) and prints their FLIP. Build it against an installed drift with
// examples/CMakeLists.txt (find_package(drift)), or:
//   cc -std=c11 render_frame.c $(pkg-config --cflags --libs drift) -o render_frame
// Usage: render_frame SCENE OUT_PREFIX [WIDTH [SPP]]
#include <drift/drift.h>
#include <stdio.h>
#include <stdlib.h>

static int check(drift_result r, const char *what)
{
    if (r != DRIFT_OK) {
        fprintf(stderr, "render_frame: %s: %s\n", what, drift_result_string(r));
    }
    return r == DRIFT_OK;
}

// PREFIX-NAME.exr (linear) and PREFIX-NAME.png (tone-mapped).
static int write_image(drift_context *ctx, const char *prefix, const char *name,
                       const drift_image *image)
{
    char path[4096];
    snprintf(path, sizeof path, "%s-%s.exr", prefix, name);
    drift_image_layer layer = { .name = NULL, .image = image };
    int ok = check(drift_image_save_exr(ctx, path, &layer, 1), path);
    snprintf(path, sizeof path, "%s-%s.png", prefix, name);
    ok = ok && check(drift_image_save_png(ctx, path, image, NULL), path);
    printf("wrote %s-%s.exr and .png (%dx%d)\n", prefix, name, image->width, image->height);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: render_frame SCENE OUT_PREFIX [WIDTH [SPP]]\n");
        return 2;
    }
    int width = argc > 3 ? atoi(argv[3]) : 128;
    unsigned spp = argc > 4 ? (unsigned)atoi(argv[4]) : 64;
    printf("libdrift %s (built against %s)\n", drift_version(), DRIFT_VERSION);

    drift_context *ctx = NULL;
    drift_scene *scene = NULL;
    drift_accel *accel = NULL;
    drift_hybrid *frame = NULL;
    drift_pt *pt = NULL;
    int ok = check(drift_context_create(&(drift_context_desc){ 0 }, &ctx), "context") &&
             check(drift_scene_load(ctx, argv[1], &scene), argv[1]) &&
             check(drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel), "accel");
    // The scene camera's aspect at the asked width.
    int height = ok ? width * scene->camera.height / scene->camera.width : 0;

    // The hybrid frame: one sample a pixel, a technique an effect.
    drift_hybrid_params params = drift_hybrid_params_recommended();
    params.width = width;
    params.height = height;
    ok = ok && check(drift_hybrid_create(ctx, scene, accel, &params, &frame), "hybrid") &&
         check(drift_hybrid_render(frame, &scene->camera, NULL), "hybrid render") &&
         write_image(ctx, argv[2], "hybrid", drift_hybrid_image(frame));

    // The reference: the path tracer at spp samples a pixel.
    drift_image reference = { 0 };
    drift_pt_params pt_params = { .width = width, .height = height, .max_depth = 8 };
    ok = ok && check(drift_pt_create(ctx, scene, accel, &pt_params, &pt), "pt") &&
         check(drift_pt_render_samples(pt, spp, NULL), "pt render") &&
         check(drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &reference), "resolve") &&
         write_image(ctx, argv[2], "reference", &reference);

    // How far the hybrid frame is from the reference.
    double flip = 0.0;
    ok = ok &&
         check(drift_metric_flip(ctx, &reference, drift_hybrid_image(frame), NULL, &flip, NULL),
               "flip");
    if (ok) {
        printf("FLIP(reference, hybrid) = %.4f\n", flip);
    }
    drift_pt_destroy(pt);
    drift_hybrid_destroy(frame);
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
    return ok ? 0 : 1;
}

// Axis-aligned filtering's hooks (frame/family.h): its settings (their defaults follow the
// frame's --spp) and its state (drift_aaf_of: made empty with the frame, its buffers by its
// passes on first use, kept across frames).
#include "aaf/aaf.h"

static void resolve(drift_hybrid_params *p, const drift_scene *scene)
{
    (void)scene;
    drift_aaf_settings_resolve(&p->aaf, p->spp);
}

static const char *problem(const drift_hybrid_params *p)
{
    return drift_aaf_settings_problem(&p->aaf, p->spp);
}

// The samples a pixel took, n(x), averaged over the pixels that took any (a glossy row
// samples only the pixels with a glossy lobe), and how many pixels those are, for each chosen
// AAF row (shadows: summed over the lights).
static void report_lobe(drift_frame_state *f, drift_family_count_fn count, const drift_image *spp,
                        const char *mean_name, const char *pixels_name)
{
    uint64_t n = 0;
    double mean = drift_family_nonzero_mean(f, spp, &n);
    count(f, mean_name, mean);
    count(f, pixels_name, (double)n);
}

static void report(drift_frame_state *f, drift_family_count_fn count)
{
    const drift_aaf_state *st = drift_aaf_buffers(f);
    if (!st) {
        return;
    }
    if (f->params.shadows == DRIFT_SHADOWS_AAF && st->lights && st->light_count > 0) {
        double samples = 0.0;
        uint64_t pixels = 0;
        for (uint32_t l = 0; l < st->light_count; ++l) {
            uint64_t n = 0;
            samples += drift_family_nonzero_mean(f, &st->lights[l].spp, &n) * (double)n;
            pixels += n;
        }
        count(f, "aaf.shadows.mean_spp", pixels ? samples / (double)pixels : 0.0);
        count(f, "aaf.shadows.sampled_pixels", (double)pixels);
    }
    if (f->params.indirect == DRIFT_INDIRECT_AAF) {
        report_lobe(f, count, &st->indirect.spp, "aaf.indirect.mean_spp",
                    "aaf.indirect.sampled_pixels");
    }
    if (f->params.reflections == DRIFT_REFLECTIONS_AAF) {
        report_lobe(f, count, &st->specular.spp, "aaf.reflections.mean_spp",
                    "aaf.reflections.sampled_pixels");
    }
    if (f->stats.rays[DRIFT_PASS_AAF_SAMPLING] > 0) {
        count(f, "aaf.sampling_rays", (double)f->stats.rays[DRIFT_PASS_AAF_SAMPLING]);
    }
}

const drift_family drift_aaf_family = {
    .name = "aaf",
    .slot = DRIFT_FAMILY_AAF,
    .create = drift_aaf_state_create,
    .resolve = resolve,
    .problem = problem,
    .destroy = drift_aaf_state_destroy,
    .report = report,
};

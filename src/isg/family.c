// Image space gathering's hooks (frame/family.h): its settings and its state (drift_isg_of:
// made empty with the frame, its buffers by its passes on first use, kept across frames).
#include "isg/isg.h"

static void resolve(drift_hybrid_params *p, const drift_scene *scene)
{
    drift_isg_settings_resolve(&p->isg, scene);
}

static const char *problem(const drift_hybrid_params *p)
{
    return drift_isg_settings_problem(&p->isg);
}

// The samples the chosen ISG rows took, read from their search planes: a pixel gathered where
// its gather radius is half a pixel or more (gather samples = those pixels x --isg-gather);
// the shadows' search runs at every surface pixel of every light (unless the light covers
// under half a pixel). The blur rows gather every surface pixel over a fixed disk.
static void report(drift_frame_state *f, drift_family_count_fn count)
{
    const drift_isg_state *s = drift_isg_buffers(f);
    if (!s) {
        return;
    }
    uint64_t surface = drift_family_surface_pixels(f);
    double search = f->params.isg.search, gather = f->params.isg.gather;
    if (f->params.shadows == DRIFT_SHADOWS_ISG && s->light_search) {
        uint64_t gathered = 0;
        for (uint32_t l = 0; l < s->light_count && l < f->light_count; ++l) {
            gathered += drift_family_surface_at_least(f, &s->light_search[l], 1, 0.5f);
        }
        count(f, "isg.shadows.search_samples", (double)surface * f->light_count * search);
        count(f, "isg.shadows.gathered_pixels", (double)gathered);
        count(f, "isg.shadows.gather_samples", (double)gathered * gather);
    } else if (f->params.shadows == DRIFT_SHADOWS_BLUR) {
        count(f, "isg.shadows.gather_samples", (double)surface * f->light_count * gather);
    }
    if (f->params.reflections == DRIFT_REFLECTIONS_ISG) {
        uint64_t gathered = drift_family_surface_at_least(f, &s->reflection_search, 1, 0.5f);
        count(f, "isg.reflections.gathered_pixels", (double)gathered);
        count(f, "isg.reflections.gather_samples", (double)gathered * gather);
    }
    if (f->params.dof == DRIFT_DOF_ISG) {
        uint64_t gathered = drift_family_surface_at_least(f, &s->dof_search, 0, 0.5f);
        count(f, "isg.dof.gathered_pixels", (double)gathered);
        count(f, "isg.dof.gather_samples", (double)gathered * gather);
    }
}

const drift_family drift_isg_family = {
    .name = "isg",
    .slot = DRIFT_FAMILY_ISG,
    .create = drift_isg_create,
    .resolve = resolve,
    .problem = problem,
    .destroy = drift_isg_destroy,
    .report = report,
};

// Axis-aligned filtering's hooks (frame/family.h): its settings (their defaults follow the
// frame's --spp) and its buffers (frame->aaf, made by its passes on first use, kept across
// frames).
#include "frame/family.h"

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

static void destroy(drift_frame_state *f)
{
    drift_aaf_state_destroy(f->ctx, f->aaf);
    f->aaf = NULL;
}

const drift_family drift_aaf_family = {
    .name = "aaf",
    .resolve = resolve,
    .problem = problem,
    .destroy = destroy,
};

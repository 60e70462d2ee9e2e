// Imperfect shadow maps' hooks (frame/family.h): its settings. Its drift_ism (VPLs, scene
// points, maps) lives in the indirect effect's state slot across frames (ism_pass.c).
#include "frame/family.h"

#include "drift/ism.h"
#include "ism/ism_pass.h"

static const char *problem(const drift_hybrid_params *p)
{
    return drift_ism_settings_problem(&p->ism);
}

// What the indirect row's drift_ism did in its last render.
static void report(drift_frame_state *f, drift_family_count_fn count)
{
    const drift_ism *ism = drift_ism_pass_object(f);
    if (!ism) {
        return;
    }
    drift_ism_stats s = drift_ism_get_stats(ism);
    count(f, "ism.vpls", s.vpl_count);
    if (f->params.indirect == DRIFT_INDIRECT_ISM) {
        count(f, "ism.splats", (double)s.splats);
        count(f, "ism.hole_fraction", s.hole_fraction);
    } else {
        count(f, "ism.shadow_rays", (double)s.shadow_rays);
    }
    count(f, "ism.near_field_rays", (double)s.near_field_rays);
    count(f, "ism.fallback_pixels", (double)s.fallback_pixels);
}

const drift_family drift_ism_family = {
    .name = "ism",
    .problem = problem,
    .report = report,
};

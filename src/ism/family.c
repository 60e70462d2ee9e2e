// Imperfect shadow maps' hooks (frame/family.h): its settings. Its drift_ism (VPLs, scene
// points, maps) lives in the indirect effect's state slot across frames (ism_pass.c).
#include "frame/family.h"

#include "ism/ism_pass.h"

static const char *problem(const drift_hybrid_params *p)
{
    return drift_ism_settings_problem(&p->ism);
}

const drift_family drift_ism_family = {
    .name = "ism",
    .problem = problem,
};

// Image space gathering's hooks (frame/family.h): its settings and its buffers (frame->isg,
// made by its passes on first use, kept across frames).
#include "frame/family.h"

#include "isg/isg.h"

static void resolve(drift_hybrid_params *p, const drift_scene *scene)
{
    drift_isg_settings_resolve(&p->isg, scene);
}

static const char *problem(const drift_hybrid_params *p)
{
    return drift_isg_settings_problem(&p->isg);
}

const drift_family drift_isg_family = {
    .name = "isg",
    .resolve = resolve,
    .problem = problem,
    .destroy = drift_isg_destroy,
};

// Micro-rendering's hooks (frame/family.h). Its drift_micro (points, hierarchy) lives in each
// effect's state slot across frames (micro_pass.c).
#include "frame/family.h"

#include "drift/micro.h"
#include "micro/micro_pass.h"

// What each micro-rendering row's drift_micro did in its last render (its points are the
// scene's, made once and kept across frames).
static void report(drift_frame_state *f, drift_family_count_fn count)
{
    static const struct {
        drift_effect effect;
        const char *points, *gathers, *rays, *photons;
    } rows[] = {
        { DRIFT_EFFECT_INDIRECT, "micro.indirect.points", "micro.indirect.gathers",
          "micro.indirect.rays", "micro.indirect.photons" },
        { DRIFT_EFFECT_REFLECTIONS, "micro.reflections.points", "micro.reflections.gathers",
          "micro.reflections.rays", "micro.reflections.photons" },
    };

    for (size_t i = 0; i < sizeof rows / sizeof *rows; ++i) {
        const drift_micro *micro = drift_micro_pass_object(f, rows[i].effect);
        if (!micro) {
            continue;
        }
        drift_micro_stats s = drift_micro_get_stats(micro);
        count(f, rows[i].points, drift_micro_get_params(micro).point_count);
        count(f, rows[i].gathers, (double)s.gathers);
        count(f, rows[i].rays, (double)s.rays);
        if (s.photons > 0) {
            count(f, rows[i].photons, (double)s.photons);
        }
    }
}

const drift_family drift_micro_family = {
    .name = "micro",
    .report = report,
};

// Screen-space occlusion's hooks (frame/family.h): contact shadows after a shadow-map row
// (--contact-shadows: the maps' bias, fixed in screen space) and their counts, kept in the
// family's state (drift_ssdo_family_of). The occlusion rows' per-frame buffers live in the
// occlusion effect's state slot (ssdo_pass.c).
#include "ssdo/ssdo_pass.h"

static drift_result create(drift_frame_state *f, void **out_state)
{
    *out_state = drift_alloc(f->ctx, sizeof(drift_ssdo_family_state));
    return *out_state ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
}

static void destroy(drift_frame_state *f, void *state)
{
    drift_free(f->ctx, state);
}

static drift_result after_row(drift_frame_state *f, const drift_family_row *row)
{
    if (row->args->effect == DRIFT_EFFECT_SHADOWS && (row->inputs & DRIFT_INPUT_SHADOW_MAPS) &&
        f->params.shadow_map.contact_shadows) {
        return drift_ssdo_pass_contact_shadows(f);
    }
    return DRIFT_OK;
}

// What the occlusion row's screen-space render did: its samples a pixel, the points marched
// along each, the bounce, the extra views and layers, and the pixels it shaded.
static void report(drift_frame_state *f, drift_family_count_fn count)
{
    // The contact shadows: they ran after this frame's shadow-map row (the after_row hook).
    if (f->params.shadow_map.contact_shadows && (f->inputs & DRIFT_INPUT_SHADOW_MAPS)) {
        const drift_ssdo_contact_counts *k = &drift_ssdo_family_of(f)->contact;
        count(f, "ssdo.contact_shadows.lights", k->lights);
        count(f, "ssdo.contact_shadows.lit_pixels", (double)k->lit_pixels);
        count(f, "ssdo.contact_shadows.march_samples", (double)k->lit_pixels * k->samples);
        count(f, "ssdo.contact_shadows.shadowed_pixels", (double)k->shadowed_pixels);
    }
    drift_ssdo_pass_counts c;
    if (!drift_ssdo_pass_report(f, &c)) {
        return;
    }
    count(f, "ssdo.samples", c.samples);
    count(f, "ssdo.steps", c.steps);
    count(f, "ssdo.bounce", c.bounce ? 1.0 : 0.0);
    count(f, "ssdo.views", c.views);
    count(f, "ssdo.layers", c.layers);
    count(f, "ssdo.shaded_pixels", (double)c.pixels);
}

const drift_family drift_ssdo_family = {
    .name = "ssdo",
    .slot = DRIFT_FAMILY_SSDO,
    .create = create,
    .destroy = destroy,
    .after_row = after_row,
    .report = report,
};

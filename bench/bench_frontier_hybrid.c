// drift bench frontier's drift rows (bench_frontier.c has the path tracer's, the reference and
// the table): hybrid frames over the search space the knob table describes, and SIR's
// refinements of the frame it is made for.
#include "bench_frontier.h"
#include "drift/hybrid.h"
#include "drift/knobs.h"
#include "drift/refine.h"

#include <stdio.h>
#include <string.h>

// One hybrid frame: a warm-up render (it builds what the frame caches across frames), then
// the frontier_median frame ms of --runs renders, stopping after the first when that one is already
// over `limit_ms` (twice the largest budget: the row holds none of them). The warm-up is never
// the row's time: a first frame pays one-time work (the ISM's scene points: 12 s on the
// Breakfast Room at 1024 VPLs) that a viewer pays once.
static drift_result hybrid_row(frontier_state *b, const char *name,
                               const drift_hybrid_params *params, double limit_ms)
{
    const frontier_options *o = b->o;
    drift_hybrid *frame = NULL;
    drift_result r = drift_hybrid_create(b->ctx, b->scene, b->accel, params, &frame);
    double ms[100];
    long n = 0;
    r = r ? r : drift_hybrid_render(frame, &b->scene->camera, NULL);
    while (r == DRIFT_OK && n < o->runs && (n == 0 || ms[0] <= limit_ms)) {
        r = drift_hybrid_render(frame, &b->scene->camera, NULL);
        ms[n++] = drift_hybrid_get_stats(frame).frame_ms;
    }
    if (r == DRIFT_OK) {
        r = frontier_add_row(b, FAMILY_HYBRID, name, frontier_median(ms, n),
                             drift_hybrid_image(frame));
    }
    drift_hybrid_destroy(frame);
    return r;
}

// The hybrid search space, from the technique table's searched rows (DRIFT_ROW_FRONTIER:
// shadows hard, pcss, isg, aaf x indirect none, ambient, aaf, ism, ir) and the knob table
// (drift/knobs.h): each knob
// swept below is set through drift_knob_set (its row's range refuses a value out of it) and
// swept only where its row says it acts: the effect's technique is among the row's
// techniques (ism-vpls on ism and ir; --spp only on a path-traced technique, AAF's rows at
// 1, 2 and 4). The sweeps: ism-vpls over --vpls (16..1024), ism-near-field off up to
// --near-field-off-vpls, ism-gather-scale 2 from --half-gather-vpls, light-samples over
// --light-samples (8), on a scene with an environment env-filter 0 and --env-filter (with
// env-scale 1 and 2), aa over --aa (1, 4). Every other knob keeps its row's default
// (drift_hybrid_params_default: what drift render --mode hybrid starts from, so a row is
// the frame the chooser's pick renders). The other effects keep the technique that matches
// the reference: reflections none on a scene without glossy or mirror materials (else isg:
// AAF's reflections scored only ~0.006 lower FLIP on the glossy box at 11-15x the frame time,
// docs/frontier.md), depth of field none for a pinhole camera (else post: reference would
// path-trace the whole frame through the lens, replacing every other row's output),
// occlusion none, glare none. Max depth 8.
typedef enum sweep_knob {
    SWEEP_VPLS,
    SWEEP_NEAR_FIELD,
    SWEEP_GATHER_SCALE,
    SWEEP_LIGHT_SAMPLES,
    SWEEP_ENV_FILTER,
    SWEEP_ENV_SCALE,
    SWEEP_AA,
    SWEEP_COUNT
} sweep_knob;

static const char *const sweep_names[SWEEP_COUNT] = {
    "ism-vpls", "ism-near-field", "ism-gather-scale", "light-samples", "env-filter", "env-scale",
    "aa"
};

// Whether the knob acts on the frame `p` chooses: a whole-frame knob always; else where its
// effect's technique is among the row's techniques (NULL: every one).
static bool knob_acts(const drift_knob *knob, const drift_hybrid_params *p)
{
    if (knob->effect < 0 || !knob->techniques) {
        return true;
    }
    const char *name = drift_technique_name((drift_effect)knob->effect,
                                            drift_hybrid_params_technique(p, knob->effect));
    size_t n = name ? strlen(name) : 0;
    for (const char *t = knob->techniques; n && (t = strstr(t, name)) != NULL; t += n) {
        bool starts = t == knob->techniques || t[-1] == ' ';
        if (starts && (t[n] == '\0' || t[n] == ' ')) {
            return true;
        }
    }
    return false;
}

// Sets the swept knob `k` to `value` where it acts on `p`; false where it does not act or
// its row refuses the value (the row is then not rendered).
static bool sweep_set(drift_hybrid_params *p, const int index[SWEEP_COUNT], sweep_knob k,
                      double value)
{
    const drift_knob *knob = drift_knob_get(index[k]);
    return knob && knob_acts(knob, p) && drift_knob_set(p, index[k], value);
}

drift_result frontier_hybrid_rows(frontier_state *b, double limit_ms)
{
    const frontier_options *o = b->o;
    int index[SWEEP_COUNT];
    for (int k = 0; k < SWEEP_COUNT; ++k) {
        if ((index[k] = drift_knob_find(sweep_names[k])) < 0) {
            fprintf(stderr, "drift bench frontier: the knob table has no %s\n", sweep_names[k]);
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
    }
    bool glossy = false;
    for (uint32_t m = 0; m < b->scene->material_count; ++m) {
        const drift_material *mat = &b->scene->materials[m];
        glossy = glossy || !drift_vec3_is_zero(mat->specular);
    }
    const bool lens = b->scene->camera.aperture_radius > 0.0f;
    const size_t ef_count = o->env_filter > 0 && drift_scene_has_environment(b->scene) ? 2 : 1;
    drift_result r = DRIFT_OK;
    // The searched rows of the technique table (DRIFT_ROW_FRONTIER), in its order.
    for (int ts = 0; ts < drift_technique_count(DRIFT_EFFECT_SHADOWS) && r == DRIFT_OK; ++ts) {
        for (int ti = 0; ti < drift_technique_count(DRIFT_EFFECT_INDIRECT) && r == DRIFT_OK; ++ti) {
            if (!drift_technique_frontier(DRIFT_EFFECT_SHADOWS, ts) ||
                !drift_technique_frontier(DRIFT_EFFECT_INDIRECT, ti)) {
                continue;
            }
            drift_hybrid_params base = drift_hybrid_params_default();
            base.width = base.height = (int32_t)o->size;
            base.max_depth = FRONTIER_DEPTH;
            drift_hybrid_params_set_technique(&base, DRIFT_EFFECT_SHADOWS, ts);
            drift_hybrid_params_set_technique(&base, DRIFT_EFFECT_INDIRECT, ti);
            drift_hybrid_params_set_technique(
                &base, DRIFT_EFFECT_REFLECTIONS,
                drift_technique_parse(DRIFT_EFFECT_REFLECTIONS, glossy ? "isg" : "none"));
            drift_hybrid_params_set_technique(
                &base, DRIFT_EFFECT_DOF,
                drift_technique_parse(DRIFT_EFFECT_DOF, lens ? "post" : "none"));
            drift_hybrid_params_set_technique(
                &base, DRIFT_EFFECT_OCCLUSION,
                drift_technique_parse(DRIFT_EFFECT_OCCLUSION, "none"));
            base.glare = DRIFT_GLARE_NONE;
            const bool vpl = knob_acts(drift_knob_get(index[SWEEP_VPLS]), &base);
            const bool traced = drift_technique_path_traced(DRIFT_EFFECT_SHADOWS, ts) ||
                                drift_technique_path_traced(DRIFT_EFFECT_INDIRECT, ti);
            const size_t vpl_count = vpl ? (size_t)o->vpl_count : 1;
            const size_t spp_count = traced ? (size_t)o->aaf_spp_count : 1;
            const size_t ls_count = (size_t)o->light_sample_count;
            const size_t variants = spp_count * ls_count * ef_count * (size_t)o->aa_count;
            for (size_t v = 0; v < vpl_count * 3 && r == DRIFT_OK; ++v) {
                // v / 3 is the VPL count; v % 3 == 1 the same rows without the near field,
                // v % 3 == 2 gathering at one pixel in 2 x 2.
                const bool near_field_off = v % 3 == 1, half_gather = v % 3 == 2;
                if ((near_field_off && (!vpl || o->vpls[v / 3] > o->near_field_off_vpls)) ||
                    (half_gather &&
                     (!vpl || o->half_gather_vpls == 0 || o->vpls[v / 3] < o->half_gather_vpls))) {
                    continue;
                }
                for (size_t k = 0; k < variants && r == DRIFT_OK; ++k) {
                    // k: the spp fastest, then the light samples, the environment filter
                    // (off, on) and the anti-aliasing passes.
                    const long aa = o->aa[k / (spp_count * ls_count * ef_count)];
                    const long ls = o->light_samples[(k / spp_count) % ls_count];
                    const bool ef = (k / (spp_count * ls_count)) % ef_count == 1;
                    const long spp = traced ? o->aaf_spps[k % spp_count] : 1;
                    drift_hybrid_params p = base;
                    p.spp = (uint32_t)spp;
                    bool ok =
                        sweep_set(&p, index, SWEEP_LIGHT_SAMPLES, (double)ls) &&
                        sweep_set(&p, index, SWEEP_AA, (double)aa) &&
                        sweep_set(&p, index, SWEEP_ENV_FILTER, ef ? (double)o->env_filter : 0.0) &&
                        sweep_set(&p, index, SWEEP_ENV_SCALE, ef ? 2.0 : 1.0);
                    if (vpl) {
                        ok = ok && sweep_set(&p, index, SWEEP_VPLS, (double)o->vpls[v / 3]) &&
                             sweep_set(&p, index, SWEEP_NEAR_FIELD, near_field_off ? 1.0 : 0.0) &&
                             sweep_set(&p, index, SWEEP_GATHER_SCALE, half_gather ? 2.0 : 1.0);
                    }
                    char name[96];
                    int len = snprintf(name, sizeof name, "%s + %s",
                                       drift_technique_name(DRIFT_EFFECT_SHADOWS, ts),
                                       drift_technique_name(DRIFT_EFFECT_INDIRECT, ti));
                    if (vpl) {
                        len += snprintf(name + len, sizeof name - (size_t)len, " %ld VPLs%s",
                                        o->vpls[v / 3],
                                        near_field_off ? " nf off"
                                        : half_gather  ? " g2"
                                                       : "");
                    }
                    if (traced) {
                        len += snprintf(name + len, sizeof name - (size_t)len, " %ld spp", spp);
                    }
                    if (ls != DEFAULT_LIGHT_SAMPLES) {
                        len += snprintf(name + len, sizeof name - (size_t)len, " ls %ld", ls);
                    }
                    if (ef) {
                        len += snprintf(name + len, sizeof name - (size_t)len, " ef %ld",
                                        o->env_filter);
                    }
                    if (aa > 1) {
                        snprintf(name + len, sizeof name - (size_t)len, " aa %ld", aa);
                    }
                    if (!ok) {
                        fprintf(stderr,
                                "drift bench frontier: %s: a knob refuses its value; "
                                "not rendered\n",
                                name);
                        continue;
                    }
                    r = hybrid_row(b, name, &p, limit_ms);
                }
            }
        }
    }
    return r;
}

// Smart image refinement (docs/sir.md) of the frame it is made for: shadows pcss, reflections
// envmap on a glossy scene (else none), depth of field post with a lens, indirect none (SIR's
// Whitted-style tracer has no indirect light, so a refined pixel would lose the raster's).
// One refinement per --sir-iterations count (one sample budget a pixel an iteration, SIR's
// default): a row's ms are the warm raster frame's plus the refinement's (metrics, sort,
// tracing), as drift report's sir cell counts them; the frontier_median of --runs refinements.
drift_result frontier_sir_rows(frontier_state *b, double limit_ms)
{
    const frontier_options *o = b->o;
    bool glossy = false;
    for (uint32_t m = 0; m < b->scene->material_count; ++m) {
        glossy = glossy || !drift_vec3_is_zero(b->scene->materials[m].specular);
    }
    drift_hybrid_params p = {
        .width = (int32_t)o->size,
        .height = (int32_t)o->size,
        .max_depth = FRONTIER_DEPTH,
        .shadows = DRIFT_SHADOWS_PCSS,
        .reflections = glossy ? DRIFT_REFLECTIONS_ENVMAP : DRIFT_REFLECTIONS_NONE,
        .dof = b->scene->camera.aperture_radius > 0.0f ? DRIFT_DOF_POST : DRIFT_DOF_NONE
    };
    drift_hybrid *frame = NULL;
    drift_result r = drift_hybrid_create(b->ctx, b->scene, b->accel, &p, &frame);
    r = r ? r : drift_hybrid_render(frame, &b->scene->camera, NULL); // warm-up
    double raster[100];
    long n = 0;
    while (r == DRIFT_OK && n < o->runs) {
        r = drift_hybrid_render(frame, &b->scene->camera, NULL);
        raster[n++] = drift_hybrid_get_stats(frame).frame_ms;
    }
    double raster_ms = r == DRIFT_OK ? frontier_median(raster, n) : 0.0;
    for (int k = 0; k < o->sir_count && r == DRIFT_OK; ++k) {
        double ms[100];
        drift_refine *sir = NULL;
        for (long run = 0; run < o->runs && r == DRIFT_OK; ++run) {
            drift_refine_destroy(sir);
            sir = NULL;
            r = drift_refine_create(b->ctx, frame, &(drift_refine_params){ 0 }, &sir);
            double t = drift_time_now();
            r = r ? r : drift_refine_begin(sir);
            while (r == DRIFT_OK && !drift_refine_done(sir) &&
                   drift_refine_get_stats(sir).iterations < (uint32_t)o->sir[k]) {
                r = drift_refine_iterate(sir, NULL);
            }
            ms[run] = raster_ms + 1e3 * (drift_time_now() - t);
        }
        if (r == DRIFT_OK) {
            char name[96];
            snprintf(name, sizeof name, "pcss%s + none, %ld iterations", glossy ? " + envmap" : "",
                     o->sir[k]);
            r = frontier_add_row(b, FAMILY_SIR, name, frontier_median(ms, o->runs),
                                 drift_refine_image(sir));
        }
        bool over = r == DRIFT_OK && b->rows[b->row_count - 1].ms > limit_ms;
        bool done = sir && drift_refine_done(sir); // every error pixel refined: no more to show
        drift_refine_destroy(sir);
        if (over || done) {
            break;
        }
    }
    drift_hybrid_destroy(frame);
    return r;
}

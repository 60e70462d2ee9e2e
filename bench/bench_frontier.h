// drift bench frontier's internals shared by its files: the options, the rows and the
// per-scene state (bench_frontier.c: one scene; bench_frontier_corpus.c: --corpus, one table
// over many scenes, and the path tracer at reduced resolution upsampled).
#ifndef DRIFT_BENCH_FRONTIER_H
#define DRIFT_BENCH_FRONTIER_H

#include "bench.h"
#include "drift/accel.h"
#include "drift/denoise.h"
#include "drift/scene.h"
#include "render.h"

#define MAX_BUDGETS    16
#define MAX_ROWS       512
#define FRONTIER_DEPTH RENDER_WHOLE_FRAME_DEPTH
// The hybrid frame's own default (drift_hybrid_params.light_samples = 0 -> 8); a row at
// another count is named with it.
#define DEFAULT_LIGHT_SAMPLES 8
#define REF_SEED              RENDER_WHOLE_FRAME_REF_SEED

typedef struct frontier_options {
    const char *scene_path, *csv_path, *svg_path, *cache_dir;
    long size, threads, ref_spp, runs, max_spp, near_field_off_vpls, half_gather_vpls, env_filter;
    long budgets[MAX_BUDGETS], vpls[MAX_BUDGETS], aaf_spps[MAX_BUDGETS], aa[MAX_BUDGETS],
        sir[MAX_BUDGETS], light_samples[MAX_BUDGETS];
    int budget_count, vpl_count, aaf_spp_count, aa_count, sir_count, light_sample_count;
    const char *corpus_path; // --corpus DIR|LIST: one table over the scenes
    bool json;
} frontier_options;

typedef enum row_family {
    FAMILY_PT = 0,
    FAMILY_PT_ATROUS,
    FAMILY_HYBRID,
    FAMILY_SIR,
    FAMILY_PT_LOW,        // the path tracer at 1/2 or 1/4 resolution, upsampled
    FAMILY_PT_LOW_ATROUS, // the same through a-trous before the upsampling
    FAMILY_PT_DENOISE,    // the path tracer + drift's best denoiser (`--denoise on`)
    FAMILY_HYBRID_PT,     // the default hybrid frame + the path tracer, combined by
                          // drift_denoise_guided (both renders and the filter paid)
    FAMILY_COUNT
} row_family;

// best_within's family for a drift technique of either kind: a hybrid frame, or one refined
// by SIR.
#define FAMILY_DRIFT (-2)

extern const char *const family_names[FAMILY_COUNT];

// The hybrid+pt rows' guides: the default hybrid frame; the same with 256 VPLs gathered at one
// pixel in 2 x 2 ("cheap"); the same with indirect none ("direct"): cheaper guides whose
// indirect light's bias the residual corrects.
#define FRONTIER_GUIDES 3

typedef struct frontier_row {
    char name[96];
    row_family family;
    double ms, flip, rmse;
} frontier_row;

typedef struct frontier_state {
    drift_context *ctx;
    const drift_scene *scene;
    const drift_accel *accel;
    const frontier_options *o;
    drift_image reference;
    frontier_row rows[MAX_ROWS];
    int row_count;
    drift_image guide[FRONTIER_GUIDES]; // hybrid frames (frontier_guide_frame); no pixels: none
    drift_image guide_indirect[FRONTIER_GUIDES]; // their "indirect" planes (none: no pixels)
    double guide_ms[FRONTIER_GUIDES];            // their warm frames' median ms
} frontier_state;

// Loads the cached reference or renders and caches it; *cached says which.
drift_result frontier_reference_image(frontier_state *b, const char *scene_path, bool *cached,
                                      char *path, size_t path_size);
// One row: its FLIP and RMSE against the reference, progress on stderr.
drift_result frontier_add_row(frontier_state *b, row_family family, const char *name, double ms,
                              const drift_image *image);
// The path tracer at `spp`, the same through a-trous and through drift's best denoiser (the
// feature-guided one); *out_ms: the render's median.
drift_result frontier_pt_rows(frontier_state *b, long spp, double *out_ms);
drift_result frontier_hybrid_rows(frontier_state *b, double limit_ms);
// The guides (FRONTIER_GUIDES: drift_hybrid_params_default at the bench's size, max depth 8,
// glare none, depth of field none for a pinhole camera, and its cheaper variants), their warm
// frames' median ms, into b->guide: frontier_pt_rows then adds the hybrid+pt rows
// (bench_frontier_guided.c).
drift_result frontier_guide_frame(frontier_state *b);
// The hybrid+pt rows of one path-traced image (its AOVs as drift_denoise_feature takes them):
// each guide and filter, ms = the guide's + render_ms + the filter's (one timing: the last
// of --runs renders).
drift_result frontier_guided_rows(frontier_state *b, long spp, double render_ms,
                                  const drift_denoise_inputs *in);
drift_result frontier_sir_rows(frontier_state *b, double limit_ms);
// The row of `family` (-1: any; FAMILY_DRIFT: hybrid or sir) with the lowest FLIP within
// `budget` ms, or -1.
int frontier_best_within(const frontier_state *b, int family, double budget);
double frontier_median(double *v, long n);

// The path tracer at 1/2 and 1/4 of the size (spp doubling until over limit_ms), upsampled
// bilinearly and by a joint-bilateral filter guided by a full-resolution G-buffer (depth,
// normal, albedo from camera rays, its time counted), with and without a-trous at the low
// resolution: what a user does when one sample a pixel does not fit (bench_frontier_corpus.c).
drift_result frontier_low_res_rows(frontier_state *b, double limit_ms);
// --corpus: every scene of a folder or a list file, one table scene x budget.
int frontier_corpus(frontier_options *o);

#endif // DRIFT_BENCH_FRONTIER_H

// The real-time renderer's techniques, the baselines every later technique is measured
// against: direct light as U_l x S_l with hard ray-traced shadows or shadow maps filtered by
// PCF or PCSS (direct.c), and reflections from one sharp mirror ray or a cube environment map
// captured at a probe (reflections.c), ambient light and post-process depth of field (screen.c).
// docs/hybrid.md has the equations.
#ifndef DRIFT_REALTIME_H
#define DRIFT_REALTIME_H

#include "frame/family.h"

// --- THE FAMILY'S STATE (family.c) ---

// An environment probe: one for the whole scene, or one per reflective mesh.
typedef struct drift_realtime_probe {
    uint32_t mesh; // DRIFT_INVALID_INDEX for the scene probe
    drift_envmap *map;
} drift_realtime_probe;

// What the real-time family keeps across frames, in its slot of the frame (frame/family.h):
// made by its create hook, dropped by its update hook when a knob they depend on changes,
// freed by its destroy hook. Other families read the maps and probes through the accessors
// below (contact shadows, SIR's metrics).
typedef struct drift_realtime_state {
    drift_shadow_map **shadow_maps; // per light: built on first use, kept while the scene and
                                    // the map settings stand
    uint32_t light_count;
    drift_realtime_probe *probes; // captured on first use, kept while the settings stand
    uint32_t probe_count;
    // The environment prefiltered by GGX roughness (the split sum's lookup; built on first
    // use by the unshadowed pass, kept while the scene stands).
    drift_env_prefilter *env_prefilter;
} drift_realtime_state;

static inline drift_realtime_state *drift_realtime_of(const drift_frame_state *frame)
{
    return (drift_realtime_state *)drift_family_state(frame, DRIFT_FAMILY_REALTIME);
}

// Light `light`'s shadow map, or NULL where none is built.
static inline const drift_shadow_map *drift_realtime_shadow_map(const drift_frame_state *frame,
                                                                uint32_t light)
{
    const drift_realtime_state *s = drift_realtime_of(frame);
    return s && light < s->light_count ? s->shadow_maps[light] : NULL;
}

// The probe that serves `mesh` (its own, or the scene's), or NULL where none is captured.
const drift_envmap *drift_realtime_probe_of(const drift_frame_state *frame, uint32_t mesh);

// --- SETTINGS (settings.c) ---

// Fills zero settings with their defaults (drift/hybrid.h), and says what is wrong with
// resolved ones (NULL: nothing).
void drift_realtime_settings_resolve(drift_shadow_map_settings *shadow_map,
                                     drift_envmap_settings *envmap);
const char *drift_realtime_settings_problem(const drift_shadow_map_settings *shadow_map,
                                            const drift_envmap_settings *envmap);

// --- INPUTS OTHER TECHNIQUES READ TOO (direct.c, reflections.c) ---

// U_l of every light and the ray-traced environment term for every pixel.
drift_result drift_realtime_pass_unshadowed(drift_frame_state *frame);
// The hard-shadow buffer: one ray toward each light's centre; S_l = those bits.
// One ray a pixel a light toward its centre. With `occluder_distances` false (no row reads
// them) a light whose own surface the ray cannot meet (drift_raster_light.shadow_clearance)
// takes any-hit rays, 30% cheaper than closest hits, and its occluder channel holds 0 where
// the pixel is in shadow.
drift_result drift_realtime_pass_hard_shadows(drift_frame_state *frame, bool occluder_distances);
// Shadow maps of every light, built on first use and kept while the scene and the map
// settings stand (SIR's penumbra metric reads them too).
drift_result drift_realtime_build_shadow_maps(drift_frame_state *frame);
// One light's shadow map, built if the cache has none; adds the rays it casts to *rays.
drift_result drift_realtime_ensure_shadow_map(drift_frame_state *frame, uint32_t light,
                                              uint64_t *rays);
// Frees light `light`'s shadow map (the next use builds it again).
void drift_realtime_drop_shadow_map(drift_frame_state *frame, uint32_t light);
// The sharp reflection buffer: one mirror ray a glossy or mirror pixel, R from it.
drift_result drift_realtime_pass_sharp_reflections(drift_frame_state *frame);
// Adds to R the light smooth glass lets through (traced as the sharp pass does) at the
// glass pixels, after a reflection row that does not trace it (no DRIFT_ROW_TRACES_GLASS).
drift_result drift_realtime_pass_glass_transmission(drift_frame_state *frame);
// The environment-map probes, captured on first use (kept while the settings stand).
drift_result drift_realtime_capture_probes(drift_frame_state *frame);
// The direction R looks `map` up in for a reflected ray from p along dir: dir, or with
// envmap.parallax = BOX the box-projected direction (drift_envmap_parallax_direction over
// the scene's bounds; *cone, the lobe's half angle, then scaled to its footprint as the probe
// sees it).
drift_vec3 drift_realtime_envmap_direction(const drift_frame_state *frame, const drift_envmap *map,
                                           drift_vec3 p, drift_vec3 dir, float *cone);

// --- TECHNIQUES ---

// S_l by a shadow-map lookup: percentage-closer filtering over params.shadow_map.pcf_kernel texels,
// or percentage-closer soft shadows (Fernando 2005: blocker search, penumbra estimate, PCF).
drift_result drift_realtime_pass_pcf(drift_frame_state *frame, const drift_pass_args *args);
drift_result drift_realtime_pass_pcss(drift_frame_state *frame, const drift_pass_args *args);
// D = sum_l U_l S_l + environment: after any technique that writes S_l.
drift_result drift_realtime_pass_sum_direct(drift_frame_state *frame);
// R from the environment map (probes captured first).
drift_result drift_realtime_pass_envmap_reflections(drift_frame_state *frame,
                                                    const drift_pass_args *args);
// I = albedo x a constant ambient radiance (params.ambient, or the mean of D) (screen.c).
drift_result drift_realtime_pass_ambient(drift_frame_state *frame, const drift_pass_args *args);
// final = the post-process depth of field of focus over the coc plane (screen.c).
drift_result drift_realtime_pass_post_dof(drift_frame_state *frame, const drift_pass_args *args);

#endif // DRIFT_REALTIME_H

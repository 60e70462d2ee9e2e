// drift bind: what a language binding (Python's ctypes, cffi, a DCC plug-in) needs beyond the
// other headers, in calls that pass only pointers and plain numbers: the hybrid frame's
// parameters behind a pointer (no struct layout mirrored in the binding), set by name with
// the names of the command line's options (an effect and a technique, or a knob of the knob
// table, drift/knobs.h, such as "ism-vpls", also written "ism_vpls" or "ism.vpls"); the scene's
// camera; and a reference render into a caller-owned image. python/drift (docs/python.md) is built
// on it.
//
// STEP BY STEP
//   drift_hybrid_params *p = drift_bind_params_new();       // drift_hybrid_params_recommended()
//   drift_bind_params_set(p, "shadows", "pcss");              // an effect and a technique
//   drift_bind_params_set(p, "ism.vpls", "256");              // a knob (drift_bind_knob_name)
//   drift_hybrid_create(ctx, scene, accel, p, &frame);
//   drift_hybrid_render(frame, drift_bind_scene_camera(scene), NULL);
//   drift_bind_params_free(p);
#ifndef DRIFT_BIND_H
#define DRIFT_BIND_H

#include "drift/accel.h"
#include "drift/core.h"
#include "drift/hybrid.h"
#include "drift/image.h"
#include "drift/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

// A new drift_hybrid_params holding drift_hybrid_params_recommended() (NULL when out of
// memory); drift_bind_params_free releases it (NULL-safe).
drift_hybrid_params *drift_bind_params_new(void);
void drift_bind_params_free(drift_hybrid_params *params);

// Sets one parameter by name: an effect's name ("shadows", drift_effect_name) with one of its
// technique names ("pcss", drift_technique_name), or a knob (drift_bind_knob_name) with the
// text its command-line option takes ("256", "on", "auto"). DRIFT_ERR_INVALID_ARGUMENT for an
// unknown name, or a value that does not parse whole or is outside the knob's range.
drift_result drift_bind_params_set(drift_hybrid_params *params, const char *name,
                                   const char *value);
// The knob's value as a double (bools 0 or 1); NAN for an unknown name.
double drift_bind_params_get(const drift_hybrid_params *params, const char *name);

// The knobs drift_bind_params_set takes, the frame's width, height, seed, spp and max_depth
// then the knob table's rows: index < drift_bind_knob_count(), else NULL.
uint32_t drift_bind_knob_count(void);
const char *drift_bind_knob_name(uint32_t index);
const char *drift_bind_knob_type(uint32_t index); // "int", "uint", "float" or "choice"

// The scene's camera (borrowed from the scene).
const drift_camera *drift_bind_scene_camera(const drift_scene *scene);

// The path tracer's image of the scene camera at width x height (0: the camera's size), spp
// samples a pixel, seed, max_depth (0: 8), into *out_image, a new RGB image owned by the
// caller (drift_image_destroy). Errors as drift_pt_create and drift_pt_render_samples.
drift_result drift_bind_reference(drift_context *ctx, const drift_scene *scene,
                                  const drift_accel *accel, int32_t width, int32_t height,
                                  uint32_t spp, uint32_t seed, int32_t max_depth,
                                  drift_image *out_image);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_BIND_H

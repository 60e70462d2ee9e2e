// drift techniques: the table of the hybrid frame's techniques, one row per (effect,
// technique). Everything that lists techniques iterates these rows: the enums and names of
// drift/hybrid.h, the command line's flags and --help, the viewer's keys and overlay, stats,
// --aov planes, the benchmarks' sweeps and the tests. docs/adding-a-technique.md walks
// through adding a row.
//
// Techniques, X(P, ENUM, name, summary, pass, inputs, flags, planes, stream, components), with
// P the effect's constant prefix (passed through):
//   ENUM        the suffix of the public constant (DRIFT_SHADOWS_ENUM, ...)
//   name        the stable name the command line, stats files and the viewer use
//   summary     one line for --help and the viewer's overlay
//   pass        the function that fills the effect's term (drift_pass_none: the inputs are it)
//   inputs      DRIFT_INPUT_* the frame prepares before the pass (buffers shared by rows)
//   flags       DRIFT_ROW_*: how the conductor treats the row's output, and whether the
//               equal-time frontier searches the row (DRIFT_ROW_FRONTIER)
//   planes      the function that lists the row's own --aov planes (drift_planes_none: none)
//   stream      the sampler stream the pass keys its random numbers on (0: none)
//   components  DRIFT_PT_COMPONENT_* of the effect's path-traced truth (its `reference` row)
// Only the library's conductor (src/hybrid/techniques.c) expands the implementation columns;
// the public header uses ENUM, name and summary. The rows of an effect are in the order of
// its enum: append new rows at the end, so that existing values keep their meaning.
#ifndef DRIFT_TECHNIQUES_H
#define DRIFT_TECHNIQUES_H

// Effects, X(ENUM, name, type, TECHNIQUES, kind, plane):
//   ENUM        DRIFT_EFFECT_ENUM, and the prefix of its techniques' constants (DRIFT_ENUM_...)
//   name        the effect's name: the command line's --name, and its field in
//               drift_hybrid_params (params.name)
//   type        drift_<type>_technique is the enum of its techniques
//   TECHNIQUES  the list of its rows (below)
//   kind        TERM: its rows fill one term of L = E + D + R + I + ... (in effect order);
//               POST: its rows turn the composed frame (focus) into the final image
//   plane       the --aov plane of what its rows write
// A new effect is one more line here and its list of techniques.
#define DRIFT_EFFECTS(X)                                                                      \
    X(SHADOWS, shadows, shadow, DRIFT_SHADOW_TECHNIQUES, TERM, "direct")                      \
    X(REFLECTIONS, reflections, reflection, DRIFT_REFLECTION_TECHNIQUES, TERM, "reflections") \
    X(DOF, dof, dof, DRIFT_DOF_TECHNIQUES, POST, "final")                                     \
    X(INDIRECT, indirect, indirect, DRIFT_INDIRECT_TECHNIQUES, TERM, "indirect")              \
    X(OCCLUSION, occlusion, occlusion, DRIFT_OCCLUSION_TECHNIQUES, TERM, "occlusion")         \
    X(GLARE, glare, glare, DRIFT_GLARE_TECHNIQUES, POST, "final")

#define DRIFT_SHADOW_TECHNIQUES(X, P)                                                              \
    X(P, HARD, "hard", "ray-traced visibility of each light's centre", drift_pass_none,            \
      DRIFT_INPUT_UNSHADOWED | DRIFT_INPUT_HARD_SHADOWS,                                           \
      DRIFT_ROW_SUMS_DIRECT | DRIFT_ROW_FRONTIER, drift_planes_none, 0, DRIFT_PT_COMPONENT_DIRECT) \
    X(P, PCF, "pcf", "shadow map, percentage-closer filtering", drift_realtime_pass_pcf,           \
      DRIFT_INPUT_UNSHADOWED | DRIFT_INPUT_SHADOW_MAPS, DRIFT_ROW_SUMS_DIRECT, drift_planes_none,  \
      0, DRIFT_PT_COMPONENT_DIRECT)                                                                \
    X(P, PCSS, "pcss", "shadow map, percentage-closer soft shadows (Fernando 2005)",               \
      drift_realtime_pass_pcss, DRIFT_INPUT_UNSHADOWED | DRIFT_INPUT_SHADOW_MAPS,                  \
      DRIFT_ROW_SUMS_DIRECT | DRIFT_ROW_FRONTIER, drift_planes_none, DRIFT_STREAM_PCSS,            \
      DRIFT_PT_COMPONENT_DIRECT)                                                                   \
    X(P, REFERENCE, "reference", "direct light path-traced at --spp", drift_hybrid_pass_reference, \
      0, DRIFT_ROW_PATH_TRACED, drift_planes_none, 0, DRIFT_PT_COMPONENT_DIRECT)                   \
    X(P, ISG, "isg", "image space gathering over the hard-shadow buffer (docs/isg.md)",            \
      drift_isg_pass_shadows,                                                                      \
      DRIFT_INPUT_UNSHADOWED | DRIFT_INPUT_HARD_SHADOWS | DRIFT_INPUT_OCCLUDER_DISTANCES,          \
      DRIFT_ROW_SUMS_DIRECT | DRIFT_ROW_FRONTIER, drift_isg_shadow_planes,                         \
      DRIFT_STREAM_ISG_SHADOWS, DRIFT_PT_COMPONENT_DIRECT)                                         \
    X(P, BLUR, "blur", "baseline: the hard-shadow bits blurred over a fixed disk",                 \
      drift_isg_pass_shadows,                                                                      \
      DRIFT_INPUT_UNSHADOWED | DRIFT_INPUT_HARD_SHADOWS | DRIFT_INPUT_OCCLUDER_DISTANCES,          \
      DRIFT_ROW_SUMS_DIRECT, drift_planes_none, DRIFT_STREAM_ISG_SHADOWS,                          \
      DRIFT_PT_COMPONENT_DIRECT)                                                                   \
    X(P, AAF, "aaf", "axis-aligned filtering of ray-traced area-light visibility (docs/aaf.md)",   \
      drift_aaf_pass_shadows, DRIFT_INPUT_UNSHADOWED,                                              \
      DRIFT_ROW_SUMS_DIRECT | DRIFT_ROW_PATH_TRACED | DRIFT_ROW_FRONTIER, drift_aaf_shadow_planes, \
      DRIFT_STREAM_AAF_SHADOWS, DRIFT_PT_COMPONENT_DIRECT)

#define DRIFT_REFLECTION_TECHNIQUES(X, P)                                                          \
    X(P, NONE, "none", "no reflections", drift_pass_none, 0, DRIFT_ROW_NO_TERM, drift_planes_none, \
      0, DRIFT_PT_COMPONENT_SPECULAR)                                                              \
    X(P, ENVMAP, "envmap", "cube map captured at a probe point",                                   \
      drift_realtime_pass_envmap_reflections, DRIFT_INPUT_PROBES, 0, drift_planes_none, 0,         \
      DRIFT_PT_COMPONENT_SPECULAR)                                                                 \
    X(P, SHARP, "sharp", "one mirror ray per pixel", drift_pass_none,                              \
      DRIFT_INPUT_SHARP_REFLECTIONS, DRIFT_ROW_TRACES_GLASS, drift_planes_none, 0,                 \
      DRIFT_PT_COMPONENT_SPECULAR)                                                                 \
    X(P, REFERENCE, "reference", "first-bounce glossy and mirror light path-traced at --spp",      \
      drift_hybrid_pass_reference, 0, DRIFT_ROW_PATH_TRACED | DRIFT_ROW_TRACES_GLASS,              \
      drift_planes_none, 0, DRIFT_PT_COMPONENT_SPECULAR)                                           \
    X(P, ISG, "isg", "image space gathering over the sharp buffer (docs/isg.md)",                  \
      drift_isg_pass_reflections, DRIFT_INPUT_SHARP_REFLECTIONS, DRIFT_ROW_TRACES_GLASS,           \
      drift_isg_reflection_planes, DRIFT_STREAM_ISG_REFLECTIONS, DRIFT_PT_COMPONENT_SPECULAR)      \
    X(P, BLUR, "blur", "baseline: the sharp buffer blurred over a fixed disk",                     \
      drift_isg_pass_reflections, DRIFT_INPUT_SHARP_REFLECTIONS, DRIFT_ROW_TRACES_GLASS,           \
      drift_planes_none, DRIFT_STREAM_ISG_REFLECTIONS, DRIFT_PT_COMPONENT_SPECULAR)                \
    X(P, AAF, "aaf", "glossy light path-traced, adaptively sampled and filtered (docs/aaf.md)",    \
      drift_aaf_pass_specular, 0, DRIFT_ROW_PATH_TRACED, drift_aaf_specular_planes,                \
      DRIFT_STREAM_AAF_SPECULAR, DRIFT_PT_COMPONENT_SPECULAR)                                      \
    X(P, MICRO, "micro", "glossy final gather into micro-buffers (thesis ch. 6, docs/micro.md)",   \
      drift_micro_pass_reflections, 0, 0, drift_micro_reflection_planes, 0,                        \
      DRIFT_PT_COMPONENT_SPECULAR)

#define DRIFT_DOF_TECHNIQUES(X, P)                                                           \
    X(P, NONE, "none", "pinhole: everything in focus", drift_hybrid_pass_pinhole, 0, 0,      \
      drift_planes_none, 0, 0)                                                               \
    X(P, POST, "post", "gather over the circle of confusion in image space",                 \
      drift_realtime_pass_post_dof, 0, 0, drift_planes_none, 0, DRIFT_PT_COMPONENT_ALL)      \
    X(P, REFERENCE, "reference", "the whole frame path-traced through the thin lens",        \
      drift_hybrid_pass_lens_reference, 0, DRIFT_ROW_PATH_TRACED | DRIFT_ROW_REPLACES_FRAME, \
      drift_planes_none, 0, DRIFT_PT_COMPONENT_ALL)                                          \
    X(P, ISG, "isg", "image space gathering over the focused frame (docs/isg.md)",           \
      drift_isg_pass_dof, 0, 0, drift_isg_dof_planes, DRIFT_STREAM_ISG_DOF,                  \
      DRIFT_PT_COMPONENT_ALL)

#define DRIFT_INDIRECT_TECHNIQUES(X, P)                                                           \
    X(P, NONE, "none", "no indirect light", drift_pass_none, 0,                                   \
      DRIFT_ROW_NO_TERM | DRIFT_ROW_FRONTIER, drift_planes_none, 0, DRIFT_PT_COMPONENT_DIFFUSE)   \
    X(P, AMBIENT, "ambient", "diffuse albedo x a constant radiance", drift_realtime_pass_ambient, \
      0, DRIFT_ROW_FRONTIER, drift_planes_none, 0, DRIFT_PT_COMPONENT_DIFFUSE)                    \
    X(P, REFERENCE, "reference", "first-bounce diffuse light path-traced at --spp",               \
      drift_hybrid_pass_reference, 0, DRIFT_ROW_PATH_TRACED, drift_planes_none, 0,                \
      DRIFT_PT_COMPONENT_DIFFUSE)                                                                 \
    X(P, AAF, "aaf",                                                                              \
      "diffuse indirect path-traced, adaptively sampled and filtered (docs/aaf.md)",              \
      drift_aaf_pass_indirect, 0, DRIFT_ROW_PATH_TRACED | DRIFT_ROW_FRONTIER,                     \
      drift_aaf_indirect_planes, DRIFT_STREAM_AAF_INDIRECT, DRIFT_PT_COMPONENT_DIFFUSE)           \
    X(P, ISM, "ism", "virtual point lights, imperfect shadow maps (thesis ch. 5, docs/ism.md)",   \
      drift_ism_pass_indirect, 0, DRIFT_ROW_FRONTIER, drift_ism_indirect_planes, 0,               \
      DRIFT_PT_COMPONENT_DIFFUSE)                                                                 \
    X(P, IR, "ir", "baseline: the same VPLs with ray-traced visibility (instant radiosity)",      \
      drift_ism_pass_ir, 0, DRIFT_ROW_FRONTIER, drift_ism_indirect_planes, 0,                     \
      DRIFT_PT_COMPONENT_DIFFUSE)                                                                 \
    X(P, MICRO, "micro", "final gather into point-hierarchy micro-buffers (thesis ch. 6)",        \
      drift_micro_pass_indirect, 0, 0, drift_micro_indirect_planes, 0, DRIFT_PT_COMPONENT_DIFFUSE)

// Light from the environment through the diffuse lobe, with its visibility (thesis ch. 4). Any
// technique but none takes that light out of D (DRIFT_ROW_ENVIRONMENT_DIFFUSE).
#define DRIFT_OCCLUSION_TECHNIQUES(X, P)                                                         \
    X(P, NONE, "none", "the environment stays in D, ray-traced at --light-samples",              \
      drift_pass_none, 0, DRIFT_ROW_NO_TERM, drift_planes_none, 0, DRIFT_PT_COMPONENT_DIRECT)    \
    X(P, SSAO, "ssao", "ambient occlusion x one pre-filtered environment lookup (docs/ssdo.md)", \
      drift_ssdo_pass_ssao, 0, DRIFT_ROW_ENVIRONMENT_DIFFUSE, drift_ssdo_planes, 0,              \
      DRIFT_PT_COMPONENT_DIRECT)                                                                 \
    X(P, GTAO, "gtao", "ground-truth AO with bent normals (Jimenez et al. 2016)",                \
      drift_ssdo_pass_gtao, 0, DRIFT_ROW_ENVIRONMENT_DIFFUSE, drift_ssdo_planes, 0,              \
      DRIFT_PT_COMPONENT_DIRECT)                                                                 \
    X(P, SSDO, "ssdo", "screen-space directional occlusion, one bounce (thesis ch. 4)",          \
      drift_ssdo_pass_ssdo, 0, DRIFT_ROW_ENVIRONMENT_DIFFUSE, drift_ssdo_planes, 0,              \
      DRIFT_PT_COMPONENT_DIRECT)                                                                 \
    X(P, REFERENCE, "reference", "the environment's diffuse light, --spp shadow rays a pixel",   \
      drift_ssdo_pass_reference, 0, DRIFT_ROW_ENVIRONMENT_DIFFUSE | DRIFT_ROW_PATH_TRACED,       \
      drift_planes_none, 0x55d10000, DRIFT_PT_COMPONENT_DIRECT)

// The human eye's scattering of the final HDR frame (thesis ch. 8), after depth of field.
#define DRIFT_GLARE_TECHNIQUES(X, P)                                                               \
    X(P, NONE, "none", "no glare: the frame as a camera sees it", drift_pass_none, 0,              \
      DRIFT_ROW_NO_TERM, drift_planes_none, 0, 0)                                                  \
    X(P, STATIC, "static", "the eye at rest: one PSF (docs/glare.md)", drift_glare_pass_static, 0, \
      0, drift_planes_none, 0, 0)                                                                  \
    X(P, DYNAMIC, "dynamic", "the eye in motion: pupil, hippus, lens, blinks (docs/glare.md)",     \
      drift_glare_pass_dynamic, 0, 0, drift_planes_none, 0, 0)

#endif // DRIFT_TECHNIQUES_H

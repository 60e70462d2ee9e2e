// The real-time techniques' settings: shadow maps (pcf, pcss) and environment maps (envmap),
// their defaults (drift/hybrid.h) and their checks.
#include "realtime/realtime.h"

#include <math.h>

void drift_realtime_settings_resolve(drift_shadow_map_settings *shadow_map,
                                     drift_envmap_settings *envmap)
{
    shadow_map->size = shadow_map->size ? shadow_map->size : 512;
    shadow_map->bias = shadow_map->bias > 0.0f ? shadow_map->bias : 1.5f;
    shadow_map->pcf_kernel = shadow_map->pcf_kernel ? shadow_map->pcf_kernel : 3;
    shadow_map->contact_samples = shadow_map->contact_samples ? shadow_map->contact_samples : 8;
    envmap->size = envmap->size ? envmap->size : 128;
}

const char *drift_realtime_settings_problem(const drift_shadow_map_settings *shadow_map,
                                            const drift_envmap_settings *envmap)
{
    if (shadow_map->size < 1 || shadow_map->size > 8192 || envmap->size < 1 ||
        envmap->size > 4096) {
        return "shadow map or environment map size out of range";
    }
    if (shadow_map->pcf_kernel < 1 || shadow_map->pcf_kernel > 63) {
        return "pcf kernel outside 1..63";
    }
    if (shadow_map->contact_samples < 1 || shadow_map->contact_samples > 1024) {
        return "contact-shadow samples outside 1..1024";
    }
    if (!isfinite(shadow_map->bias) ||
        (envmap->has_probe && !drift_vec3_is_finite(envmap->probe))) {
        return "non-finite shadow bias or probe";
    }
    return NULL;
}

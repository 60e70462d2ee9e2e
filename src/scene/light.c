#include "drift/scene.h"

#include "scene_internal.h"

struct drift_light_table {
    float *cdf; // light_count + 1 entries
    float total_power;
};

drift_result drift__light_table_build(drift_scene *scene)
{
    drift__light_table_destroy(scene);
    return DRIFT_OK;
}

void drift__light_table_destroy(drift_scene *scene)
{
    if (scene->light_table) {
        drift_free(scene->ctx, scene->light_table->cdf);
        drift_free(scene->ctx, scene->light_table);
        scene->light_table = NULL;
    }
}

// Colour management through OpenColorIO 2 (Debian's libopencolorio): a config's display/view
// transform, e.g. Blender's Filmic, applied to drift's scene-linear image for the PNG. The one
// entry point is extern "C" and never lets an exception out: OCIO reports a missing file, an
// unknown display or view by throwing, which becomes a message.
#include "image_ocio.h"

#include <OpenColorIO/OpenColorIO.h>
#include <cstdio>
#include <exception>

namespace OCIO = OCIO_NAMESPACE;

extern "C" int drift__ocio_apply(const char *config_path, const char *display, const char *view,
                                 const char *look, float *rgb, size_t count, char *why,
                                 size_t why_size)
{
    try {
        OCIO::ConstConfigRcPtr config = OCIO::Config::CreateFromFile(config_path);
        const char *d = display && *display ? display : config->getDefaultDisplay();
        bool found = false;
        for (int i = 0; i < config->getNumViews(d) && !found; ++i) {
            found = std::string(config->getView(d, i)) == view;
        }
        if (!found) {
            std::string views;
            for (int i = 0; i < config->getNumViews(d); ++i) {
                views += std::string(i ? ", " : "") + config->getView(d, i);
            }
            std::snprintf(why, why_size, "%s has no view '%s' on display '%s' (its views: %s)",
                          config_path, view, d, views.c_str());
            return 1;
        }
        OCIO::DisplayViewTransformRcPtr t = OCIO::DisplayViewTransform::Create();
        t->setSrc(OCIO::ROLE_SCENE_LINEAR);
        t->setDisplay(d);
        t->setView(view);
        OCIO::ConstProcessorRcPtr processor;
        if (look && *look) {
            OCIO::LegacyViewingPipelineRcPtr pipeline = OCIO::LegacyViewingPipeline::Create();
            pipeline->setDisplayViewTransform(t);
            pipeline->setLooksOverrideEnabled(true);
            pipeline->setLooksOverride(look);
            processor = pipeline->getProcessor(config, config->getCurrentContext());
        } else {
            processor = config->getProcessor(t);
        }
        if (count == 0) {
            return 0; // a check of the names only
        }
        OCIO::ConstCPUProcessorRcPtr cpu = processor->getDefaultCPUProcessor();
        OCIO::PackedImageDesc image(rgb, static_cast<long>(count), 1, 3);
        cpu->apply(image);
        return 0;
    } catch (const std::exception &e) {
        std::snprintf(why, why_size, "%s", e.what());
    } catch (...) {
        std::snprintf(why, why_size, "OpenColorIO failed");
    }
    return 1;
}

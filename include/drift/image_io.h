// drift image_io: loading and saving images (OpenEXR, PNG, JPEG, Radiance HDR).
//
// Loading always produces linear float RGB: an image of 3 channels that the caller frees with
// drift_image_destroy. Display-encoded 8- and 16-bit files (PNG, JPEG) are decoded with the
// sRGB transfer curve; EXR and HDR files are taken as linear. Alpha is dropped (not
// premultiplied in, not kept). Saving writes OpenEXR (float32, ZIP, any number of layers) or
// a tone-mapped 8-bit sRGB PNG.
//
// Writers never leave a partial file behind: they write to a temporary file next to the
// target ("<path>.tmp-XXXXXXXX") and rename() it over the target only when everything was
// written; on failure the temporary file is removed and the target is untouched.
//
// STEP BY STEP
//   drift_image img;
//   if (drift_image_load(ctx, "render.exr", &img) != DRIFT_OK) { ... }   // detail in the log
//   drift_image_layer layers[] = { { NULL, &img }, { "albedo", &albedo } };
//   drift_image_save_exr(ctx, "out.exr", layers, 2);   // R,G,B + albedo.R, albedo.G, albedo.B
//   drift_image_save_png(ctx, "out.png", &img, &(drift_tonemap_params){ .exposure_stops = 1 });
//   drift_image_destroy(ctx, &img);
//
// Errors (every message names the path): DRIFT_ERR_IO (cannot open/read/write/rename),
// DRIFT_ERR_PARSE (corrupt or truncated content), DRIFT_ERR_UNSUPPORTED (extension or
// EXR feature such as deep data, subsampled channels, no colour channels),
// DRIFT_ERR_INVALID_ARGUMENT (bad arguments, image over DRIFT_IMAGE_MAX_DIMENSION),
// DRIFT_ERR_OUT_OF_MEMORY.
//
// Threads: all functions are thread-safe on distinct paths and images.
#ifndef DRIFT_IMAGE_IO_H
#define DRIFT_IMAGE_IO_H

#include "drift/core.h"
#include "drift/image.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

// Loads an image by file extension (case-insensitive):
//   .exr          OpenEXR (scanline or tiled, half/float/uint; level 0 of mip/rip maps). The
//                 channels used are, in order of preference: the default layer's R,G,B; its Y
//                 (grey, copied to R,G,B); the first named layer with .R,.G,.B (alphabetic).
//                 Of a multi-part file the first part with such channels is read. The image
//                 is the data window (its origin is dropped).
//   .png          8- or 16-bit, grey or colour, sRGB-decoded to linear.
//   .jpg, .jpeg   8-bit baseline/progressive, sRGB-decoded to linear.
//   .hdr          Radiance RGBE, linear.
// The content must be the format its extension names (PNG's signature, JPEG's start of image,
// Radiance's header); anything else, say a PNM or BMP behind a .png name, is DRIFT_ERR_PARSE.
// *out_image receives a 3-channel image owned by the caller (drift_image_destroy); it is
// zeroed on failure. Sizes are checked against DRIFT_IMAGE_MAX_DIMENSION before allocating.
drift_result drift_image_load(drift_context *ctx, const char *path, drift_image *out_image);

// drift_image_load of an image already in memory (a texture embedded in a .glb or a data URI),
// its format told by its bytes (PNG, JPEG, Radiance HDR, OpenEXR); `name` is for messages.
drift_result drift_image_load_memory(drift_context *ctx, const char *name, const void *data,
                                     size_t size, drift_image *out_image);

// Where a coverage image's values come from when the file has no alpha channel.
typedef enum drift_alpha_source {
    DRIFT_ALPHA_CHANNEL = 0, // 1 (glTF: a base colour image without alpha is opaque)
    DRIFT_ALPHA_OR_GREY,     // the mean of its colour channels as stored (an MTL's map_d)
} drift_alpha_source;

// The alpha channel of a PNG, JPEG or Radiance HDR (file or memory, as the two above), as
// stored (8- and 16-bit values over 255 and 65535, not sRGB-decoded), into a 1-channel image;
// where the file has none, what `source` says. OpenEXR is DRIFT_ERR_UNSUPPORTED. What a
// material's coverage reads (drift_material.opacity_texture).
drift_result drift_image_load_alpha(drift_context *ctx, const char *path, drift_alpha_source source,
                                    drift_image *out_image);
drift_result drift_image_load_alpha_memory(drift_context *ctx, const char *name, const void *data,
                                           size_t size, drift_alpha_source source,
                                           drift_image *out_image);

// One layer of a multi-layer EXR. name NULL or "" is the default layer (plain channel names);
// any other name prefixes the channels ("name.R"). Borrowed for the duration of the call.
typedef struct drift_image_layer {
    const char *name;
    const drift_image *image;
} drift_image_layer;

// Writes a single-part scanline OpenEXR file with ZIP compression and float32 channels (so a
// round trip is bit-exact). Channel names per image channel count: 1 -> Y, 2 -> Y,A,
// 3 -> R,G,B, 4 -> R,G,B,A, prefixed by "name." for named layers. All layers must have the
// same width and height; names must be unique and at most 200 bytes long, and at most one
// layer may be the default one. Errors: DRIFT_ERR_INVALID_ARGUMENT, DRIFT_ERR_IO,
// DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_image_save_exr(drift_context *ctx, const char *path,
                                  const drift_image_layer *layers, uint32_t layer_count);

// A string attribute in an EXR header (name and value borrowed for the call).
typedef struct drift_image_attribute {
    const char *name;
    const char *value;
} drift_image_attribute;

// drift_image_save_exr plus string attributes in the header ("drift.spp": how the image was
// made). Names must be unique and not those the EXR format itself defines. Every EXR drift
// writes also carries the standard `chromaticities` attribute: linear Rec.709 / sRGB
// primaries with a D65 white, the colour space drift renders in.
drift_result drift_image_save_exr_attributes(drift_context *ctx, const char *path,
                                             const drift_image_layer *layers, uint32_t layer_count,
                                             const drift_image_attribute *attributes,
                                             uint32_t attribute_count);

// drift_image_save_exr_attributes with the channels of layer i named by channels[i] instead
// of the defaults, comma-separated, one name per image channel: "X,Y,Z" for a layer "N" gives
// normals as N.X, N.Y, N.Z; "Z" for an unnamed 1-channel layer gives depth as the conventional
// Z channel (such a layer may sit beside the default R, G, B one). channels, or any entry of
// it, may be NULL: the defaults.
drift_result drift_image_save_exr_channels(drift_context *ctx, const char *path,
                                           const drift_image_layer *layers, uint32_t layer_count,
                                           const char *const *channels,
                                           const drift_image_attribute *attributes,
                                           uint32_t attribute_count);

// Writes an 8-bit RGB PNG of the image tone-mapped by drift_image_tonemap (tonemap may be NULL:
// defaults). 1-channel images are written grey in RGB; alpha is dropped. Errors:
// DRIFT_ERR_INVALID_ARGUMENT, DRIFT_ERR_IO, DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_image_save_png(drift_context *ctx, const char *path, const drift_image *image,
                                  const drift_tonemap_params *tonemap);

// Colour management through OpenColorIO (docs/colour.md): how drift_image_save_png_view
// turns the scene-linear image into display values.
typedef struct drift_ocio_view {
    const char *config;   // an OCIO config file; NULL: drift_ocio_default_config()
    const char *display;  // NULL: the config's default display ("sRGB" in Blender's)
    const char *view;     // the view transform: "Filmic", "Standard", ...
    const char *look;     // NULL: none ("Medium High Contrast", ...)
    float exposure_stops; // scales the image by 2^stops before the view (Blender's Exposure)
} drift_ocio_view;

// Whether this build has OpenColorIO (the CMake option DRIFT_OCIO found libopencolorio).
bool drift_ocio_available(void);
// The config used when none is named: $OCIO, else Blender's own (the blender-data package:
// /usr/share/blender/datafiles/colormanagement/config.ocio, or under a version folder), else
// NULL.
const char *drift_ocio_default_config(void);
// Whether the config exists and has the view's display, view and look (before a render:
// the errors drift_image_save_png_view would give, logged against `where`).
drift_result drift_ocio_check_view(drift_context *ctx, const char *where,
                                   const drift_ocio_view *view);
// Writes an 8-bit RGB PNG (with its sRGB chunk) of the image through the config's display and
// view transform. Errors: DRIFT_ERR_UNSUPPORTED (no OpenColorIO in this build, no config),
// DRIFT_ERR_INVALID_ARGUMENT (unknown display, view or look; the log says which exist),
// DRIFT_ERR_IO, DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_image_save_png_view(drift_context *ctx, const char *path,
                                       const drift_image *image, const drift_ocio_view *view);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_IMAGE_IO_H

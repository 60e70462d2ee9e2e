// Private to src/io/image_exr*.{c,cpp}: the DWAA/DWAB decoder on the OpenEXR C++ library.
// Plain C types only, so that both languages include it.
#ifndef DRIFT_IO_IMAGE_EXR_DWA_H
#define DRIFT_IO_IMAGE_EXR_DWA_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

// Decodes part `part` of the EXR file in data[0..size) into `pixels`, a zeroed width×height
// image of 3 interleaved floats per pixel, `stride` floats per row (width×height must be the
// part's data window). channel_names[k] feeds component k; NULL leaves it zero. Returns 0, or
// -1 with the library's message in `message` (corrupt data, truncated file).
int drift__exr_dwa_decode(const char *path, const uint8_t *data, size_t size, int part,
                          const char *const channel_names[3], float *pixels, ptrdiff_t stride,
                          int32_t width, int32_t height, char *message, size_t message_cap);

#ifdef __cplusplus
}
#endif

#endif

// DWAA/DWAB decoding through the OpenEXR C++ library (libOpenEXR 3.1).
//
// Debian 12's OpenEXRCore 3.1 has no DWA decoder (EXR_ERR_FEATURE_NOT_IMPLEMENTED), yet most
// HDRI libraries ship DWAB panoramas. The C++ library of the same package decodes them, so
// image_exr.c hands such parts here; everything else (the part and channel choice, limits,
// every other codec) stays on the C core. See docs/decisions/0014-exr-cxx-shim.md.
//
// The one entry point is extern "C" and never lets an exception out: the C++ library reports
// corrupt data by throwing, which becomes a message and a non-zero return.
#include "image_exr_dwa.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <cstdio>
#include <cstring>
#include <exception>

namespace
{

// The file already in memory, as an Imf::IStream (the C side read it once for the core).
class MemoryStream : public Imf::IStream
{
  public:
    MemoryStream(const char *name, const uint8_t *data, size_t size)
        : Imf::IStream(name), data_(data), size_(size)
    {
    }

    bool read(char c[], int n) override
    {
        if (n < 0 || pos_ > size_ || static_cast<size_t>(n) > size_ - pos_) {
            throw Iex::InputExc("unexpected end of file");
        }
        std::memcpy(c, data_ + pos_, static_cast<size_t>(n));
        pos_ += static_cast<size_t>(n);
        return pos_ < size_;
    }

    uint64_t tellg() override
    {
        return pos_;
    }

    void seekg(uint64_t pos) override
    {
        pos_ = pos;
    }

  private:
    const uint8_t *data_;
    size_t size_;
    uint64_t pos_ = 0;
};

} // namespace

extern "C" int drift__exr_dwa_decode(const char *path, const uint8_t *data, size_t size, int part,
                                     const char *const channel_names[3], float *pixels,
                                     ptrdiff_t stride, int32_t width, int32_t height, char *message,
                                     size_t message_cap)
{
    try {
        MemoryStream stream(path, data, size);
        // No worker threads: drift decodes on the caller's thread, as the C core does, and
        // no chunk-table reconstruction (a truncated file is an error).
        Imf::MultiPartInputFile file(stream, 0, false);
        if (part < 0 || part >= file.parts()) {
            throw Iex::ArgExc("part out of range");
        }
        Imf::InputPart input(file, part);
        const Imath::Box2i dw = input.header().dataWindow();
        if (dw.max.x - dw.min.x + 1 != width || dw.max.y - dw.min.y + 1 != height) {
            throw Iex::ArgExc("data window differs from the OpenEXRCore header");
        }
        Imf::FrameBuffer frame;
        for (int k = 0; k < 3; ++k) {
            if (channel_names[k] && input.header().channels().findChannel(channel_names[k])) {
                frame.insert(channel_names[k],
                             Imf::Slice::Make(Imf::FLOAT, pixels + k, dw, sizeof(float) * 3,
                                              sizeof(float) * static_cast<size_t>(stride)));
            }
        }
        input.setFrameBuffer(frame);
        input.readPixels(dw.min.y, dw.max.y);
        return 0;
    } catch (const std::exception &e) {
        std::snprintf(message, message_cap, "%s", e.what());
    } catch (...) {
        std::snprintf(message, message_cap, "unknown OpenEXR C++ error");
    }
    return -1;
}

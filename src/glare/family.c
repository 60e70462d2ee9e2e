// Glare's hooks (frame/family.h). Its PSFs live in the glare effect's state slot across
// frames (glare_pass.c).
#include "frame/family.h"

#include "glare/glare_pass.h"

// What the glare row's drift_glare did in the last frame: the aperture FFT and PSF sizes,
// whether the PSF was made anew, the convolution's padded FFT and the pixels convolved.
static void report(drift_frame_state *f, drift_family_count_fn count)
{
    const drift_glare *glare = drift_glare_pass_object(f);
    if (!glare) {
        return;
    }
    drift_glare_stats s = drift_glare_get_stats(glare);
    count(f, "glare.aperture_fft", s.aperture_fft);
    count(f, "glare.psf_size", s.psf_size);
    count(f, "glare.psf_updates", s.psf_updated ? 1.0 : 0.0);
    count(f, "glare.fft_width", s.fft_width);
    count(f, "glare.fft_height", s.fft_height);
    count(f, "glare.convolved_pixels", (double)s.convolved_pixels);
}

const drift_family drift_glare_family = {
    .name = "glare",
    .report = report,
};

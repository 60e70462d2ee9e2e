// drift glare: temporal glare, a dynamic human-eye scattering model applied to HDR images
// (Ritschel, Ihrke, Frisvad, Coppens, Myszkowski & Seidel 2009; Ritschel's thesis 2009, ch. 8).
//
// Each frame draws the eye's aperture (pupil, eyelids and lashes, lens particles and fibre
// gratings, vitreous, corneal and pre-retinal particles) as a transmittance image, takes its
// Fresnel diffraction pattern with one FFT (thesis eq. 8.3: |F{P E}|^2, the power spectrum),
// sums copies of that monochromatic PSF scaled per wavelength into XYZ and then linear
// Rec.709 RGB (§8.4 step 3), and convolves the HDR image with it by FFT with zero padding
// (linear, not circular). The eye is dynamic: the pupil follows the damped field luminance
// (eq. 8.2) with hippus (eq. 8.1), the lens deforms as a 17x17 mass-spring grid driven by
// accommodation microfluctuations, the vitreous is a damped rigid body kicked by saccades, and
// the lids blink. docs/glare.md gives every equation, the constants and the departures.
//
// It does not tone map (the thesis displays with gamma 2.2; drift_image_save_png applies the
// sRGB curve) and has no billboard fast path yet.
//
// STEP BY STEP
//   drift_glare *glare = NULL;
//   drift_glare_params params = { .mode = DRIFT_GLARE_MODE_DYNAMIC, .seed = 7 };
//   if (drift_glare_create(ctx, &params, &glare) != DRIFT_OK) { ... }   // detail in the log
//   for (int f = 0; f < frame_count; ++f) {
//       drift_image out;                                  // made by apply; caller destroys
//       drift_glare_apply(glare, &frames[f], f == 0 ? 0.0 : 1.0 / 30.0, &out);
//       ... save or show out ...
//       drift_image_destroy(ctx, &out);
//   }
//   drift_glare_apply_to(glare, &frame, dt, &frame);      // or in place, no allocation
//   const drift_image *psf = drift_glare_psf(glare);     // the last frame's RGB PSF (borrowed)
//   drift_glare_destroy(glare);
//
// Static mode (the default) uses the eye at t = 0 with no dynamics and caches the PSF between
// calls; dynamic mode advances the eye by dt seconds in every drift_glare_apply and recomputes
// the PSF. Given the params (seed included) and the sequence of (image, dt), every output is
// bit-identical across runs and thread counts.
//
// Ownership: drift_glare_create returns an object owned by the caller (drift_glare_destroy);
// images passed in are borrowed for the call; the images apply makes are owned by the caller.
// Threads: one drift_glare is not thread-safe (it holds the eye state and scratch buffers);
// distinct objects are. The FFT is kissfft (BSD-3), not hand-written.
#ifndef DRIFT_GLARE_H
#define DRIFT_GLARE_H

#include "drift/core.h"
#include "drift/image.h"

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

// Largest pupil diameter in mm (thesis §8.2.2, p_max of eq. 8.1).
#define DRIFT_GLARE_PUPIL_MAX_MM 9.0
// Reference wavelength of the monochromatic PSF and of the Fresnel term E, nm (thesis §8.4).
#define DRIFT_GLARE_LAMBDA_REF_NM 575.0

typedef enum drift_glare_mode {
    DRIFT_GLARE_MODE_DEFAULT = 0, // DRIFT_GLARE_MODE_STATIC
    DRIFT_GLARE_MODE_STATIC,      // the eye at t = 0, no dynamics; the PSF is made once
    DRIFT_GLARE_MODE_DYNAMIC,     // the eye advances by dt every frame
    DRIFT_GLARE_MODE_COUNT
} drift_glare_mode;

typedef enum drift_glare_pupil_model {
    DRIFT_GLARE_PUPIL_DEFAULT = 0,    // DRIFT_GLARE_PUPIL_THESIS
    DRIFT_GLARE_PUPIL_THESIS,         // thesis eq. 8.2: 4.9 - 3 tanh(0.4 (log10 L + 1))
    DRIFT_GLARE_PUPIL_MOON_SPENCER,   // Moon & Spencer 1944: 4.9 - 3 tanh(0.4 log10 L)
    DRIFT_GLARE_PUPIL_WATSON_YELLOTT, // Watson & Yellott 2012, the unified formula (eq. 21)
    DRIFT_GLARE_PUPIL_COUNT
} drift_glare_pupil_model;

typedef enum drift_glare_diffraction {
    DRIFT_GLARE_DIFFRACTION_DEFAULT = 0, // DRIFT_GLARE_DIFFRACTION_FRESNEL
    DRIFT_GLARE_DIFFRACTION_FRESNEL,     // thesis eq. 8.3 with the chirp E at 575 nm
    DRIFT_GLARE_DIFFRACTION_FRAUNHOFER,  // E = 1 (Kakimoto et al. 2004)
    DRIFT_GLARE_DIFFRACTION_COUNT
} drift_glare_diffraction;

typedef enum drift_glare_method {
    DRIFT_GLARE_METHOD_DEFAULT = 0, // DRIFT_GLARE_METHOD_CONVOLUTION
    DRIFT_GLARE_METHOD_CONVOLUTION, // the whole image by FFT (thesis §8.4 step 4, its results)
    DRIFT_GLARE_METHOD_BILLBOARD,   // the PSF pasted at bright pixels only (the fast path)
    DRIFT_GLARE_METHOD_COUNT
} drift_glare_method;

// How to make glare. Zero is the default for every field. The default configuration is:
//   mode = static, seed = 0
//   psf_size = 256 (N: the aperture and PSF are N x N; a power of two in [16, 4096])
//   supersample = 2 (the aperture is rasterised at 2N with coverage, then box-downsampled)
//   wavelength_count = 32 (380 nm + i (770 - 380) / n, thesis §8.4 step 3)
//   diffraction = Fresnel, fresnel_distance_mm = 0 -> 2 (p_max / 2)^2 / lambda_ref = 70.4 m:
//     a quarter wave of chirp phase at the edge of a 9 mm pupil (the physical 17-24 mm alias E
//     at any N <= 1024 and defocus the PSF by many waves; thesis-spec §6.4 "sampling caveat")
//   aperture_width_mm = 12 (W: physical width of the N x N aperture texture)
//   image_fov = 0 -> one PSF pixel per image pixel (the thesis's practice); > 0: the
//     horizontal field of view of the image in radians, and the PSF (angular pitch
//     lambda_ref / W) is resampled to the image's pitch fov / width
//   pupil_model = thesis eq. 8.2; wy_field_deg = 0 -> 60 (adapting field diameter, degrees),
//     wy_age = 0 -> 28.58 (years; the formula's reference age), wy_monocular = false
//   luminance_scale = 0 -> 1 (cd/m^2 per image unit, for the field luminance)
//   field_luminance = 0 -> the image's mean luminance; > 0: fixed, in cd/m^2
//   adaptation_time = 0 -> 0.4 s (time constant of the damped field luminance, log domain)
//   hippus_scale = 0 -> 0.1 (noise amplitude of eq. 8.1; negative: no hippus)
//   lens_particle_count = 0 -> 750, grating_count = 0 -> 200, vitreous_particle_count = 0 ->
//     200, cornea_particle_count = 0 -> 300, retina_particle_count = 0 -> 20 (negative: none)
//   lash_count = 0 -> 40 (per lid pair; negative: none)
//   blink_interval = 0 -> 4 s (mean; negative: no blinking), squint = 0 (lid closure 0..1)
//   accommodation_scale = 0 -> 1 (scales the lens drive; negative: no accommodation)
//   saccade_scale = 0 -> 1 (scales the vitreous forces; negative: no saccades)
//   method = convolution; billboard: pixels whose luminance is over billboard_threshold
//     (0 -> 20 x the frame's mean luminance; image units) are replaced by the PSF scaled by
//     the pixel, the brightest billboard_max (0 -> 4096) of them; the rest stays sharp
typedef struct drift_glare_params {
    drift_glare_mode mode;
    uint32_t seed;
    int32_t psf_size;
    int32_t supersample;
    int32_t wavelength_count;
    drift_glare_diffraction diffraction;
    double fresnel_distance_mm;
    double aperture_width_mm;
    double image_fov;
    drift_glare_pupil_model pupil_model;
    double wy_field_deg;
    double wy_age;
    bool wy_monocular;
    double luminance_scale;
    double field_luminance;
    double adaptation_time;
    double hippus_scale;
    int32_t lens_particle_count;
    int32_t grating_count;
    int32_t vitreous_particle_count;
    int32_t cornea_particle_count;
    int32_t retina_particle_count;
    int32_t lash_count;
    double blink_interval;
    double squint;
    double accommodation_scale;
    double saccade_scale;
    drift_glare_method method;
    double billboard_threshold;
    int32_t billboard_max;
} drift_glare_params;

// The params with every default filled in (negative counts and scales become 0).
drift_glare_params drift_glare_params_resolve(const drift_glare_params *params);

// Checks resolved-or-not params: DRIFT_ERR_INVALID_ARGUMENT with a logged reason (psf_size not
// a power of two in [16, 4096], supersample outside 1..8, wavelength_count outside 1..128,
// non-finite or out-of-range values), else DRIFT_OK.
drift_result drift_glare_params_check(drift_context *ctx, const drift_glare_params *params);

// Mean pupil diameter in mm for field luminance L (cd/m^2, > 0) under `model`; the
// Watson-Yellott model reads wy_field_deg, wy_age and wy_monocular from params (NULL:
// defaults). Pure, thread-safe.
double drift_glare_pupil_diameter(drift_glare_pupil_model model, double luminance,
                                  const drift_glare_params *params);
// The hippus amplitude factor of thesis eq. 8.1, (p_max / p) sqrt(1 - p / p_max).
double drift_glare_hippus_amplitude(double pupil_mm);

// The eye at one instant, for display and tests (a copy; plain data).
typedef struct drift_glare_eye {
    double time;              // seconds since create
    double field_luminance;   // damped field luminance, cd/m^2
    double pupil_mean_mm;     // p of eq. 8.2
    double pupil_mm;          // h(t, p) of eq. 8.1, clamped to [1.5, p_max]
    double blink;             // lid closure in [0, 1] (0 open), squint included
    double accommodation;     // lens drive, mm of the driven grid node
    double vitreous_angle[2]; // rigid-body rotation of the vitreous, radians (yaw, pitch)
} drift_glare_eye;

typedef struct drift_glare drift_glare;

// Makes a glare object: the eye's particles (seeded), the FFT plans and the E table.
// Errors: DRIFT_ERR_INVALID_ARGUMENT (see drift_glare_params_check), DRIFT_ERR_OUT_OF_MEMORY.
// *out_glare is NULL on failure.
drift_result drift_glare_create(drift_context *ctx, const drift_glare_params *params,
                                drift_glare **out_glare);
// NULL-safe.
void drift_glare_destroy(drift_glare *glare);

// Applies glare to `in` (3 or 4 channels; alpha is copied) into *out, a new image of the same
// size the caller destroys. Dynamic mode first advances the eye by dt seconds (dt >= 0; the
// first call's field luminance starts adapted to the first image); static mode ignores dt.
// The field luminance is the frame's mean Rec.709 luminance times luminance_scale (or the fixed
// field_luminance). Negative pixels are convolved like any other. Errors:
// DRIFT_ERR_INVALID_ARGUMENT (invalid image, 1-2 channels, NaN or infinite pixels, dt < 0 or
// not finite; logged with the first bad pixel), DRIFT_ERR_OUT_OF_MEMORY. *out is zeroed on
// failure.
drift_result drift_glare_apply(drift_glare *glare, const drift_image *in, double dt,
                               drift_image *out);

// drift_glare_apply into an existing image `out` of in's size and channel count (no allocation
// per frame; out may be in: the glare is applied in place). Same errors; out's pixels are
// undefined on failure.
drift_result drift_glare_apply_to(drift_glare *glare, const drift_image *in, double dt,
                                  const drift_image *out);

// Advances the eye by dt seconds against field luminance `luminance` (cd/m^2; <= 0 keeps the
// current one) and redraws the PSF, without convolving. drift_glare_apply calls it.
drift_result drift_glare_update(drift_glare *glare, double luminance, double dt);

// The last frame's buffers (borrowed; valid until the next call on glare):
//   drift_glare_aperture: N x N, 1 channel, the transmittance P in [0, 1]
//   drift_glare_psf_mono: N x N, 1 channel, F_575 (sums to 1, DC at (N/2, N/2))
//   drift_glare_psf:      K x K, 3 channels, the RGB PSF at the image's pitch, each channel
//                         summing to 1, centre at (K/2, K/2)
// Each is an empty image (pixels NULL) before the first update.
drift_image drift_glare_aperture(const drift_glare *glare);
drift_image drift_glare_psf_mono(const drift_glare *glare);
drift_image drift_glare_psf(const drift_glare *glare);
drift_glare_eye drift_glare_eye_state(const drift_glare *glare);

// What the last drift_glare_apply(_to) did: the aperture's FFT (N x N; 0 before the first
// update), the RGB PSF's size K, whether that call made the PSF anew (static mode: only the
// first call and a change of image width; dynamic: every call), and the convolution's
// zero-padded FFT size and the pixels it convolved (0 with the billboard method).
typedef struct drift_glare_stats {
    int32_t aperture_fft;
    int32_t psf_size;
    bool psf_updated;
    int32_t fft_width, fft_height;
    uint64_t convolved_pixels;
} drift_glare_stats;

drift_glare_stats drift_glare_get_stats(const drift_glare *glare);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_GLARE_H

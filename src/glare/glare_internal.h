// Internal pieces of src/glare shared by its files and by tests/unit/test_glare.c: the FFTs
// (kissfft's and the lane FFT), the eye state, the aperture rasteriser, the PSF steps and the FFT
// convolution.
#ifndef DRIFT_GLARE_INTERNAL_H
#define DRIFT_GLARE_INTERNAL_H

#include "drift/glare.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

// --- FFT ---

// A complex number laid out as kissfft's kiss_fft_cpx (float r, i).
typedef struct drift__cpx {
    float re;
    float im;
} drift__cpx;

// A 2-D complex FFT plan of height x width (any sizes kissfft takes; fastest with factors
// 2, 3, 5). Unnormalised in both directions: inverse(forward(x)) = width * height * x.
typedef struct drift__glare_fft drift__glare_fft;
drift_result drift__glare_fft_create(drift_context *ctx, int32_t width, int32_t height,
                                     bool inverse, drift__glare_fft **out_fft);
void drift__glare_fft_destroy(drift_context *ctx, drift__glare_fft *fft);
// out and in must not overlap. Not thread-safe on one plan.
void drift__glare_fft_run(const drift__glare_fft *fft, const drift__cpx *in, drift__cpx *out);

// A 2-D real FFT plan (width even): forward takes height x width floats to height x
// (width / 2 + 1) complex numbers, reading only the first `rows` rows (the rest are taken as
// zeros); inverse the other way (destroying its input), writing only the first `rows` rows.
// Unnormalised as above. Not thread-safe on one plan.
typedef struct drift__glare_rfft drift__glare_rfft;
drift_result drift__glare_rfft_create(drift_context *ctx, int32_t width, int32_t height,
                                      bool inverse, drift__glare_rfft **out_fft);
void drift__glare_rfft_destroy(drift_context *ctx, drift__glare_rfft *fft);
void drift__glare_rfft_forward(const drift__glare_rfft *fft, const float *in, int32_t rows,
                               drift__cpx *out);
void drift__glare_rfft_inverse(const drift__glare_rfft *fft, drift__cpx *in, int32_t rows,
                               float *out);
// Complex FFTs of DRIFT__GLARE_LANES sequences of n points at once (n with no prime factor
// above 5), one a SIMD lane (fft_lanes.c). Element e of the sequences is 2 * LANES floats:
// the LANES real parts, then the LANES imaginary parts. run transforms `data` using `work`
// (both n elements) and returns whichever holds the result. Unnormalised like kissfft; a plan
// is read-only, so threads share it.
#define DRIFT__GLARE_LANES 8
typedef struct drift__glare_lanes drift__glare_lanes;
drift_result drift__glare_lanes_create(drift_context *ctx, int32_t n, bool inverse,
                                       drift__glare_lanes **out);
void drift__glare_lanes_destroy(drift_context *ctx, drift__glare_lanes *plan);
float *drift__glare_lanes_run(const drift__glare_lanes *plan, float *data, float *work);
// LANES consecutive complex numbers of `count` rows `stride` apart to `count` elements, and
// back.
void drift__glare_lanes_gather(const drift__cpx *src, size_t stride, size_t count, float *dst);
void drift__glare_lanes_scatter(const float *src, size_t count, drift__cpx *dst, size_t stride);
// data = data x kernel x norm, `count` elements.
void drift__glare_lanes_multiply(float *data, const float *kernel, size_t count, float norm);
// Convolution without the spectrum's round trip: the kernel's spectrum (forward's output) in
// the lane layout (kernel_floats floats), then channel `channel` of `in` (zeros to its right
// and below, in smaller than the plan) transformed, multiplied by the kernel's spectrum and
// norm column block by column block, and transformed back into channel `channel` of `out`
// (in's size; it may be in). `spectrum`: scratch.
size_t drift__glare_rfft_kernel_floats(const drift__glare_rfft *fft);
void drift__glare_rfft_kernel_layout(const drift__glare_rfft *fft, const drift__cpx *spectrum,
                                     float *kernel);
void drift__glare_rfft_convolve(const drift__glare_rfft *forward, const drift__glare_rfft *inverse,
                                const drift_image *in, int32_t channel, const float *kernel,
                                float norm, drift__cpx *spectrum, const drift_image *out);
// The smallest even size >= n with no prime factor above 5.
int32_t drift__glare_fft_size(int32_t n);

// --- Eye ---

// One value-noise octave sum (3 octaves, Ebert et al. 2003) in [-1, 1], keyed by seed.
double drift__glare_noise3(uint32_t seed, double x);

#define DRIFT__GLARE_GRID 17

// A disk in the pupil plane (mm, centred on the optical axis, y up).
typedef struct drift__glare_disk {
    float x, y, radius;
} drift__glare_disk;

// A capsule (line of width `width` mm from a to b) in the pupil plane.
typedef struct drift__glare_line {
    float ax, ay, bx, by, width;
} drift__glare_line;

typedef struct drift__glare_lens_particle {
    float r, z, phi, radius; // rest position in the lens cross-section (mm), angle about the axis
} drift__glare_lens_particle;

typedef struct drift__glare_grating {
    float r0, r1, z, phi, width; // a radial fibre segment in the cortex
} drift__glare_grating;

typedef struct drift__glare_lash {
    float x, length, angle, width; // root along the lid (mm), length, tilt from the lid normal
    bool upper;
} drift__glare_lash;

// The dynamic eye (thesis §8.2; spec §6.7 EyeState, LensGrid, Vitreous).
typedef struct drift__glare_eye_state {
    drift_glare_eye pub;
    bool started;
    double log_luminance; // damped field luminance, log10 cd/m^2
    double rest[DRIFT__GLARE_GRID * DRIFT__GLARE_GRID][2];
    double pos[DRIFT__GLARE_GRID * DRIFT__GLARE_GRID][2];
    double vel[DRIFT__GLARE_GRID * DRIFT__GLARE_GRID][2];
    double vit_vel[2];
    double vit_force[2];
    double hf_freq, hf_phase; // the 1.3-2.1 Hz accommodation band
    int64_t saccade_slot;     // last saccade slot that kicked the vitreous
} drift__glare_eye_state;

// Static scatterers and the per-frame primitives to rasterise.
typedef struct drift__glare_scene {
    drift__glare_lens_particle *lens;
    int32_t lens_count;
    drift__glare_grating *gratings;
    int32_t grating_count;
    float (*vitreous)[4]; // x, y, z, radius
    int32_t vitreous_count;
    drift__glare_disk *static_disks; // cornea and pre-retinal particles
    int32_t static_count;
    drift__glare_lash *lashes;
    int32_t lash_count;
    // Per frame:
    drift__glare_disk *disks; // lens + vitreous + static, projected
    int32_t disk_count;
    drift__glare_line *lines; // gratings + lashes
    int32_t line_count;
} drift__glare_scene;

// Lens and eye constants (mm); docs/glare.md says where each comes from.
#define DRIFT__GLARE_LENS_RADIUS     4.5
#define DRIFT__GLARE_LENS_THICKNESS  4.0
#define DRIFT__GLARE_VITREOUS_RADIUS 8.0
#define DRIFT__GLARE_LID_OPEN        5.0
#define DRIFT__GLARE_PUPIL_MIN_MM    1.5

drift_result drift__glare_scene_create(drift_context *ctx, const drift_glare_params *p,
                                       drift__glare_scene *out_scene);
void drift__glare_scene_destroy(drift_context *ctx, drift__glare_scene *scene);
void drift__glare_eye_init(drift__glare_eye_state *eye, const drift_glare_params *p);
// Advances the eye by dt (>= 0) toward field luminance L (cd/m^2, > 0); dynamic says whether
// the dynamics run (static mode: the eye at t = 0 with the mean pupil).
void drift__glare_eye_step(drift__glare_eye_state *eye, const drift_glare_params *p,
                           double luminance, double dt, bool dynamic);
// Fills scene->disks and scene->lines from the eye state (lens lookup, vitreous rotation).
void drift__glare_scene_pose(drift__glare_scene *scene, const drift__glare_eye_state *eye,
                             const drift_glare_params *p);
// Lid edges at the current closure: the opening is y_bottom < y < y_top (mm, at x = 0; the
// lids curve by 0.02 x^2).
void drift__glare_lids(double closure, double *out_top, double *out_bottom);

// --- Aperture ---

// What to draw: a pupil disk, lids, and opaque disks and lines.
typedef struct drift__glare_aperture_desc {
    double pupil_mm; // diameter
    double closure;  // lids, 0 open .. 1 closed
    bool lids;       // draw lids at all
    const drift__glare_disk *disks;
    int32_t disk_count;
    const drift__glare_line *lines;
    int32_t line_count;
} drift__glare_aperture_desc;

// Rasterises the transmittance P into out[n * n] over a width_mm square centred on the axis
// (pixel i's centre at (i - n/2) * width_mm / n, row 0 at the top): every primitive is point
// sampled at supersample^2 positions per pixel (hires must hold (n*supersample)^2 floats) and
// the coverage is box-averaged. Disks smaller than a high-resolution pixel are splatted with
// their area (bilinear weights) so that they neither vanish nor pop.
void drift__glare_aperture_draw(const drift__glare_aperture_desc *desc, int32_t n,
                                int32_t supersample, double width_mm, float *hires, float *out);

// --- PSF ---

// The monochromatic PSF from an aperture (thesis eq. 8.3, §8.4 step 2): field = P E (E may be
// NULL: Fraunhofer), FFT, |F|^2, normalised to unit sum, fftshifted (DC at (n/2, n/2)).
// scratch holds 2 n^2 complex numbers. Returns the sum of |F|^2 before normalisation in
// *out_power (may be NULL; Parseval: n^2 sum |P E|^2).
void drift__glare_psf_mono(const drift__glare_fft *fft, const float *aperture, const drift__cpx *e,
                           int32_t n, drift__cpx *scratch, float *out_psf, double *out_power);
// The Fresnel chirp E(x, y) = exp(i pi (x^2 + y^2) / (lambda d)) at the aperture's pixel centres.
void drift__glare_fresnel_table(int32_t n, double width_mm, double lambda_nm, double distance_mm,
                                drift__cpx *out_e);
// CIE 1931 2-degree colour matching functions (Wyman, Sloan & Shirley 2013, the multi-lobe fit).
void drift__glare_cie_xyz(double lambda_nm, double out_xyz[3]);
// Bilinear lookup of an n x n image at continuous pixel coordinates (centre of pixel i is i);
// 0 outside.
double drift__glare_bilinear(const float *img, int32_t n, double x, double y);

// The chromatic PSF (thesis §8.4 step 3) resampled to k x k pixels of `ratio` PSF pixels each
// (1: the PSF's own grid), box-filtered when ratio > 1, tapered to 0 at radius k/2 (cos^2 from
// 0.7 k/2), each RGB channel normalised to unit sum, centre at (k/2, k/2). out is k*k*3 floats.
// scratch holds drift__glare_psf_rgb_scratch(k, ratio) bytes.
typedef struct drift__glare_tap {
    int32_t i0, i1;
    float w0, w1;
} drift__glare_tap;

size_t drift__glare_psf_rgb_scratch(int32_t k, double ratio);
void drift__glare_psf_rgb(const float *mono, int32_t n, int32_t wavelength_count, double ratio,
                          int32_t k, void *scratch, float *out);

// --- Convolution ---

// Linear convolution of a 3- or 4-channel image (colour channels) with a k x k x 3 PSF whose
// centre is (k/2, k/2), by FFTs zero-padded to >= (W + k/2) x (H + k/2), into `out`, an
// existing image of in's size and channel count (alpha copied; out may be in). The plans are
// made on demand and kept in *cache.
typedef struct drift__glare_conv {
    int32_t width, height; // padded size
    drift__glare_rfft *forward, *inverse;
    float *real;            // width * height
    drift__cpx *spectrum;   // height * (width/2 + 1)
    float *psf_spectrum[3]; // lane layout (drift__glare_rfft_kernel_layout)
    int32_t psf_k;          // k of the cached PSF spectra (0: none)
} drift__glare_conv;

drift_result drift__glare_convolve(drift_context *ctx, drift__glare_conv *cache,
                                   const drift_image *in, const float *psf, int32_t k,
                                   bool psf_changed, const drift_image *out);
void drift__glare_conv_release(drift_context *ctx, drift__glare_conv *cache);

#endif

// The dynamic eye of Ritschel 2009, thesis §8.2: the pupil (eqs. 8.1, 8.2) against the damped
// field luminance, the lens as a 17x17 mass-spring grid driven by accommodation, the vitreous
// as a damped rigid body kicked by saccades, the lids and lashes, and the static corneal and
// pre-retinal particles. Every random number is a hash of (seed, stream, index).
#include "drift/math.h"
#include "glare_internal.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

// Random-number streams (the second key of every hash).
enum {
    STREAM_LENS = 1,
    STREAM_GRATING,
    STREAM_VITREOUS,
    STREAM_CORNEA,
    STREAM_RETINA,
    STREAM_LASH,
    STREAM_HIPPUS,
    STREAM_ACCOMMODATION,
    STREAM_SACCADE,
    STREAM_BLINK,
};

static double unit(uint32_t seed, uint32_t stream, uint32_t i, uint32_t dim)
{
    uint32_t h = drift_hash_combine(drift_hash_combine(drift_hash_combine(seed, stream), i), dim);
    return (double)drift_u32_to_unit(h);
}

// Value noise: hashed lattice values in [-1, 1], smoothstep-interpolated (Ebert et al. 2003).
static double value_noise(uint32_t seed, double x)
{
    double fl = floor(x);
    int64_t i = (int64_t)fl;
    double f = x - fl;
    double a = 2.0 * (double)drift_u32_to_unit(drift_hash_combine(seed, (uint32_t)i)) - 1.0;
    double b = 2.0 * (double)drift_u32_to_unit(drift_hash_combine(seed, (uint32_t)(i + 1))) - 1.0;
    double s = f * f * (3.0 - 2.0 * f);
    return a + (b - a) * s;
}

double drift__glare_noise3(uint32_t seed, double x)
{
    // Three octaves, each twice the frequency and half the amplitude; / 1.75 keeps [-1, 1].
    double sum = 0.0, amp = 1.0, freq = 1.0;
    for (uint32_t o = 0; o < 3; ++o) {
        sum += amp * value_noise(drift_hash_combine(seed, o), x * freq);
        amp *= 0.5;
        freq *= 2.0;
    }
    return sum / 1.75;
}

// --- Pupil ---

double drift_glare_pupil_diameter(drift_glare_pupil_model model, double luminance,
                                  const drift_glare_params *params)
{
    double l = luminance > 1e-9 ? luminance : 1e-9;
    switch (model) {
    case DRIFT_GLARE_PUPIL_DEFAULT:
    case DRIFT_GLARE_PUPIL_THESIS:
        // Thesis §8.2.2 eq. 8.2 (log taken as log10).
        return 4.9 - 3.0 * tanh(0.4 * (log10(l) + 1.0));
    case DRIFT_GLARE_PUPIL_MOON_SPENCER:
        // Moon & Spencer 1944 as Watson & Yellott 2012 quote it (eq. 3).
        return 4.9 - 3.0 * tanh(0.4 * log10(l));
    case DRIFT_GLARE_PUPIL_WATSON_YELLOTT: {
        drift_glare_params r = drift_glare_params_resolve(params);
        // Watson & Yellott 2012 eq. 21: the Stanley & Davies 1995 formula (eq. 10) on the
        // effective corneal flux F = L a M(e), M = 0.1 for one eye, plus the age term.
        double radius = 0.5 * r.wy_field_deg;
        double area = PI * radius * radius; // deg^2
        double f = l * area * (r.wy_monocular ? 0.1 : 1.0);
        double q = pow(f / 846.0, 0.41);
        double d_sd = 7.75 - 5.75 * (q / (q + 2.0));
        return d_sd + (r.wy_age - 28.58) * (0.02132 - 0.009562 * d_sd);
    }
    case DRIFT_GLARE_PUPIL_COUNT:
        break;
    }
    return 4.9;
}

double drift_glare_hippus_amplitude(double pupil_mm)
{
    double p = pupil_mm;
    double pm = DRIFT_GLARE_PUPIL_MAX_MM;
    return p >= pm ? 0.0 : (pm / p) * sqrt(1.0 - p / pm);
}

// --- Static scatterers ---

drift_result drift__glare_scene_create(drift_context *ctx, const drift_glare_params *p,
                                       drift__glare_scene *s)
{
    memset(s, 0, sizeof(*s));
    uint32_t seed = p->seed;
    s->lens_count = p->lens_particle_count;
    s->grating_count = p->grating_count;
    s->vitreous_count = p->vitreous_particle_count;
    s->static_count = p->cornea_particle_count + p->retina_particle_count;
    s->lash_count = p->lash_count;
    s->lens = drift_alloc(ctx, sizeof(*s->lens) * (size_t)s->lens_count + 1);
    s->gratings = drift_alloc(ctx, sizeof(*s->gratings) * (size_t)s->grating_count + 1);
    s->vitreous = drift_alloc(ctx, sizeof(*s->vitreous) * (size_t)s->vitreous_count + 1);
    s->static_disks = drift_alloc(ctx, sizeof(*s->static_disks) * (size_t)s->static_count + 1);
    s->lashes = drift_alloc(ctx, sizeof(*s->lashes) * (size_t)s->lash_count + 1);
    s->disks = drift_alloc(
        ctx, sizeof(*s->disks) * (size_t)(s->lens_count + s->vitreous_count + s->static_count) + 1);
    s->lines = drift_alloc(ctx, sizeof(*s->lines) * (size_t)(s->grating_count + s->lash_count) + 1);
    if (!s->lens || !s->gratings || !s->vitreous || !s->static_disks || !s->lashes || !s->disks ||
        !s->lines) {
        drift__glare_scene_destroy(ctx, s);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }

    // Lens particles (thesis §8.2.3): rest positions by rejection sampling inside the lens
    // cross-section (an ellipse of radius R, thickness T in (r, z)), a random angle about the
    // axis, sizes varying over 10-40 um in radius.
    const double rl = DRIFT__GLARE_LENS_RADIUS, tl = DRIFT__GLARE_LENS_THICKNESS;
    for (int32_t i = 0; i < s->lens_count; ++i) {
        double r = 0.0, z = 0.0;
        for (uint32_t k = 0; k < 64; ++k) {
            // r = R sqrt(u): uniform over the disk the particle sweeps about the axis.
            r = rl * sqrt(unit(seed, STREAM_LENS, (uint32_t)i, 2 * k));
            z = tl * (unit(seed, STREAM_LENS, (uint32_t)i, 2 * k + 1) - 0.5);
            if ((r * r) / (rl * rl) + (4.0 * z * z) / (tl * tl) <= 1.0) {
                break;
            }
        }
        s->lens[i] = (drift__glare_lens_particle){
            .r = (float)r,
            .z = (float)z,
            .phi = (float)(2.0 * PI * unit(seed, STREAM_LENS, (uint32_t)i, 200)),
            .radius = (float)(0.010 + 0.030 * unit(seed, STREAM_LENS, (uint32_t)i, 201)),
        };
    }
    // Fibre gratings (§8.2.3): radial fibre membranes in the cortex (1.2-4.4 mm from the
    // axis), where the lattice diffracts into the lenticular halo.
    for (int32_t i = 0; i < s->grating_count; ++i) {
        double r0 = 1.2 + 2.8 * unit(seed, STREAM_GRATING, (uint32_t)i, 0);
        double len = 0.3 + 0.6 * unit(seed, STREAM_GRATING, (uint32_t)i, 1);
        s->gratings[i] = (drift__glare_grating){
            .r0 = (float)r0,
            .r1 = (float)fmin(r0 + len, 4.4),
            .z = (float)(0.6 * tl * (unit(seed, STREAM_GRATING, (uint32_t)i, 2) - 0.5)),
            .phi = (float)(2.0 * PI * unit(seed, STREAM_GRATING, (uint32_t)i, 3)),
            .width = 0.025f,
        };
    }
    // Vitreous particles (§8.2.4): uniform in a sphere, fixed in the rotating body.
    for (int32_t i = 0; i < s->vitreous_count; ++i) {
        double x, y, z;
        uint32_t k = 0;
        do {
            x = 2.0 * unit(seed, STREAM_VITREOUS, (uint32_t)i, 3 * k) - 1.0;
            y = 2.0 * unit(seed, STREAM_VITREOUS, (uint32_t)i, 3 * k + 1) - 1.0;
            z = 2.0 * unit(seed, STREAM_VITREOUS, (uint32_t)i, 3 * k + 2) - 1.0;
            ++k;
        } while (x * x + y * y + z * z > 1.0 && k < 64);
        const double rv = DRIFT__GLARE_VITREOUS_RADIUS;
        s->vitreous[i][0] = (float)(rv * x);
        s->vitreous[i][1] = (float)(rv * y);
        s->vitreous[i][2] = (float)(rv * z);
        s->vitreous[i][3] = (float)(0.015 + 0.045 * unit(seed, STREAM_VITREOUS, (uint32_t)i, 500));
    }
    // Corneal cells (§8.2.1): 15 um across, static and sparse over the cornea (radius 5 mm);
    // then the fewer, larger pre-retinal particles standing in for retinal scatter (§8.2.5).
    for (int32_t i = 0; i < s->static_count; ++i) {
        bool cornea = i < p->cornea_particle_count;
        uint32_t stream = cornea ? STREAM_CORNEA : STREAM_RETINA;
        double extent = cornea ? 5.0 : 4.5;
        double rr = extent * sqrt(unit(seed, stream, (uint32_t)i, 0));
        double ph = 2.0 * PI * unit(seed, stream, (uint32_t)i, 1);
        double radius = cornea ? 0.0075 : 0.05 + 0.05 * unit(seed, stream, (uint32_t)i, 2);
        s->static_disks[i] =
            (drift__glare_disk){ (float)(rr * cos(ph)), (float)(rr * sin(ph)), (float)radius };
    }
    // Eyelashes (§8.2.6): the thesis uses bitmaps (Kakimoto et al. 2004); here lashes are
    // capsules rooted along the lid edges, 60% on the upper lid, 80-120 um thick.
    for (int32_t i = 0; i < s->lash_count; ++i) {
        bool upper = i < (s->lash_count * 3 + 4) / 5;
        s->lashes[i] = (drift__glare_lash){
            .x = (float)(-6.0 + 12.0 * unit(seed, STREAM_LASH, (uint32_t)i, 0)),
            .length = (float)(0.4 + 1.2 * unit(seed, STREAM_LASH, (uint32_t)i, 1)),
            .angle = (float)(0.5 * (unit(seed, STREAM_LASH, (uint32_t)i, 2) - 0.5)),
            .width = (float)(0.08 + 0.04 * unit(seed, STREAM_LASH, (uint32_t)i, 3)),
            .upper = upper,
        };
    }
    return DRIFT_OK;
}

void drift__glare_scene_destroy(drift_context *ctx, drift__glare_scene *s)
{
    drift_free(ctx, s->lens);
    drift_free(ctx, s->gratings);
    drift_free(ctx, s->vitreous);
    drift_free(ctx, s->static_disks);
    drift_free(ctx, s->lashes);
    drift_free(ctx, s->disks);
    drift_free(ctx, s->lines);
    memset(s, 0, sizeof(*s));
}

// --- Dynamics ---

static int32_t node(int32_t i, int32_t j)
{
    return j * DRIFT__GLARE_GRID + i;
}

// The driven node: the lens equator, where the zonules pull (thesis §8.2.3 moves one element).
#define DRIVEN_I (DRIFT__GLARE_GRID - 1)
#define DRIVEN_J (DRIFT__GLARE_GRID / 2)

void drift__glare_eye_init(drift__glare_eye_state *eye, const drift_glare_params *p)
{
    memset(eye, 0, sizeof(*eye));
    const int32_t g = DRIFT__GLARE_GRID;
    for (int32_t j = 0; j < g; ++j) {
        for (int32_t i = 0; i < g; ++i) {
            int32_t k = node(i, j);
            eye->rest[k][0] = DRIFT__GLARE_LENS_RADIUS * i / (g - 1);
            eye->rest[k][1] = DRIFT__GLARE_LENS_THICKNESS * ((double)j / (g - 1) - 0.5);
            eye->pos[k][0] = eye->rest[k][0];
            eye->pos[k][1] = eye->rest[k][1];
        }
    }
    eye->hf_freq = 1.3 + 0.8 * unit(p->seed, STREAM_ACCOMMODATION, 0, 0);
    eye->hf_phase = 2.0 * PI * unit(p->seed, STREAM_ACCOMMODATION, 0, 1);
    eye->saccade_slot = -1;
    eye->pub.pupil_mean_mm = 4.9;
    eye->pub.pupil_mm = 4.9;
}

// Accommodation microfluctuations (§8.2.3): a low band below 0.6 Hz (3-octave value noise at
// 0.15, 0.3, 0.6 Hz) whose amplitude grows with the pupil (Gray, Winn & Gilmartin 1993), and a
// narrow 1.3-2.1 Hz band. Returns the driven node's radial displacement in mm.
static double accommodation(const drift__glare_eye_state *eye, const drift_glare_params *p,
                            double t)
{
    double lf = (eye->pub.pupil_mean_mm / DRIFT_GLARE_PUPIL_MAX_MM) *
                drift__glare_noise3(drift_hash_combine(p->seed, STREAM_ACCOMMODATION), 0.15 * t);
    double hf = 0.3 * sin(2.0 * PI * eye->hf_freq * t + eye->hf_phase);
    return 0.15 * p->accommodation_scale * (lf + hf);
}

// One symplectic Euler step of the 17x17 grid (springs to the 8 neighbours at their rest
// lengths, uniform stiffness, velocity damping); axis nodes stay on the axis and the driven
// node follows `drive`. The stiffness makes the lens follow its 0.15-2 Hz drive almost
// quasi-statically (a disturbance crosses the 16 cells in about 0.1 s), as a real lens does.
static void lens_step(drift__glare_eye_state *eye, double drive, double h)
{
    const int32_t g = DRIFT__GLARE_GRID;
    const double stiffness = 20000.0, damping = 150.0; // per unit mass, s^-2 and s^-1
    static const int32_t nb[8][2] = { { 1, 0 }, { -1, 0 }, { 0, 1 },  { 0, -1 },
                                      { 1, 1 }, { 1, -1 }, { -1, 1 }, { -1, -1 } };
    double force[DRIFT__GLARE_GRID * DRIFT__GLARE_GRID][2];
    for (int32_t j = 0; j < g; ++j) {
        for (int32_t i = 0; i < g; ++i) {
            int32_t k = node(i, j);
            double fx = -damping * eye->vel[k][0], fy = -damping * eye->vel[k][1];
            for (int32_t n = 0; n < 8; ++n) {
                int32_t ii = i + nb[n][0], jj = j + nb[n][1];
                if (ii < 0 || jj < 0 || ii >= g || jj >= g) {
                    continue;
                }
                int32_t m = node(ii, jj);
                double dx = eye->pos[m][0] - eye->pos[k][0], dy = eye->pos[m][1] - eye->pos[k][1];
                double rx = eye->rest[m][0] - eye->rest[k][0];
                double ry = eye->rest[m][1] - eye->rest[k][1];
                double len = sqrt(dx * dx + dy * dy), rest = sqrt(rx * rx + ry * ry);
                if (len > 1e-12) {
                    double f = stiffness * (len - rest) / len;
                    fx += f * dx;
                    fy += f * dy;
                }
            }
            force[k][0] = fx;
            force[k][1] = fy;
        }
    }
    for (int32_t j = 0; j < g; ++j) {
        for (int32_t i = 0; i < g; ++i) {
            int32_t k = node(i, j);
            if (i == DRIVEN_I && j == DRIVEN_J) {
                eye->pos[k][0] = eye->rest[k][0] + drive;
                eye->pos[k][1] = eye->rest[k][1];
                eye->vel[k][0] = eye->vel[k][1] = 0.0;
                continue;
            }
            eye->vel[k][0] += h * force[k][0];
            eye->vel[k][1] += h * force[k][1];
            if (i == 0) {
                eye->vel[k][0] = 0.0;
            }
            eye->pos[k][0] += h * eye->vel[k][0];
            eye->pos[k][1] += h * eye->vel[k][1];
        }
    }
}

// The vitreous (§8.2.4): a rigid body with damped rotation about two axes, driven by damped
// random forces that mimic saccades, integrated with forward Euler. Saccades fall in 0.3 s
// slots with probability 0.5 each.
static void vitreous_step(drift__glare_eye_state *eye, const drift_glare_params *p, double h)
{
    const double spring = 25.0, damping = 5.0, force_decay = 0.05; // s^-2, s^-1, s
    int64_t slot = (int64_t)floor(eye->pub.time / 0.3);
    if (slot != eye->saccade_slot) {
        eye->saccade_slot = slot;
        uint32_t s = (uint32_t)slot;
        if (unit(p->seed, STREAM_SACCADE, s, 0) < 0.5) {
            double a = 2.0 * PI * unit(p->seed, STREAM_SACCADE, s, 1);
            double m = 3.0 * p->saccade_scale * (0.5 + unit(p->seed, STREAM_SACCADE, s, 2));
            eye->vit_force[0] += m * cos(a);
            eye->vit_force[1] += m * sin(a);
        }
    }
    for (int32_t a = 0; a < 2; ++a) {
        double acc =
            eye->vit_force[a] - damping * eye->vit_vel[a] - spring * eye->pub.vitreous_angle[a];
        eye->pub.vitreous_angle[a] += h * eye->vit_vel[a];
        eye->vit_vel[a] += h * acc;
        eye->vit_force[a] *= exp(-h / force_decay);
    }
}

// Lid closure at time t (§8.2.6): one 0.25 s blink per interval, its start jittered over the
// interval's second half; squint keeps a constant closure.
static double blink_closure(const drift_glare_params *p, double t)
{
    double c = 0.0;
    if (p->blink_interval > 0.0) {
        const double duration = 0.25;
        int64_t slot = (int64_t)floor(t / p->blink_interval);
        for (int64_t s = slot - 1; s <= slot; ++s) {
            if (s < 0) {
                continue;
            }
            double start = p->blink_interval *
                           ((double)s + 0.5 + 0.5 * unit(p->seed, STREAM_BLINK, (uint32_t)s, 0));
            if (t >= start && t < start + duration) {
                c = fmax(c, sin(PI * (t - start) / duration));
            }
        }
    }
    return fmax(c, p->squint);
}

void drift__glare_lids(double closure, double *out_top, double *out_bottom)
{
    // The upper lid travels most of the way (it meets the lower one 1 mm below the axis).
    const double y0 = DRIFT__GLARE_LID_OPEN;
    *out_top = y0 - closure * (y0 + 1.0);
    *out_bottom = -y0 + closure * (y0 - 1.0);
}

void drift__glare_eye_step(drift__glare_eye_state *eye, const drift_glare_params *p,
                           double luminance, double dt, bool dynamic)
{
    double log_l = log10(luminance > 1e-6 ? luminance : 1e-6);
    if (!eye->started || !dynamic) {
        eye->log_luminance = log_l;
        eye->started = true;
        dt = 0.0;
    } else {
        // Damped field luminance (Durand & Dorsey 2000), exponential in log10 L.
        eye->log_luminance += (log_l - eye->log_luminance) * (1.0 - exp(-dt / p->adaptation_time));
    }
    eye->pub.field_luminance = pow(10.0, eye->log_luminance);
    double mean = drift_glare_pupil_diameter(p->pupil_model, eye->pub.field_luminance, p);
    mean = fmin(fmax(mean, DRIFT__GLARE_PUPIL_MIN_MM), DRIFT_GLARE_PUPIL_MAX_MM);
    eye->pub.pupil_mean_mm = mean;
    if (!dynamic) {
        eye->pub.pupil_mm = mean;
        eye->pub.blink = p->squint;
        eye->pub.accommodation = 0.0;
        return;
    }

    // Sub-steps of at most 1 ms keep the grid (a node's period is 2 pi / sqrt(8 k) = 16 ms)
    // and the Euler vitreous stable for any frame dt.
    int32_t steps = (int32_t)ceil(dt / 0.001);
    double h = steps > 0 ? dt / steps : 0.0;
    for (int32_t s = 0; s < steps; ++s) {
        eye->pub.time += h;
        double drive = accommodation(eye, p, eye->pub.time);
        eye->pub.accommodation = drive;
        lens_step(eye, drive, h);
        vitreous_step(eye, p, h);
    }
    // Thesis eq. 8.1: h(t, p) = p + noise(t / p) (p_max / p) sqrt(1 - p / p_max), the noise
    // scaled by hippus_scale (its amplitude is not printed), clamped to [1.5, p_max].
    double t = eye->pub.time;
    double noise =
        p->hippus_scale * drift__glare_noise3(drift_hash_combine(p->seed, STREAM_HIPPUS), t / mean);
    double hp = mean + noise * drift_glare_hippus_amplitude(mean);
    eye->pub.pupil_mm = fmin(fmax(hp, DRIFT__GLARE_PUPIL_MIN_MM), DRIFT_GLARE_PUPIL_MAX_MM);
    eye->pub.blink = blink_closure(p, t);
}

// Bilinear lookup of the grid's displacement at rest coordinates (r, z).
static void lens_lookup(const drift__glare_eye_state *eye, double r, double z, double *out_r,
                        double *out_z)
{
    const int32_t g = DRIFT__GLARE_GRID;
    double u = r / DRIFT__GLARE_LENS_RADIUS * (g - 1);
    double v = (z / DRIFT__GLARE_LENS_THICKNESS + 0.5) * (g - 1);
    u = fmin(fmax(u, 0.0), g - 1.000001);
    v = fmin(fmax(v, 0.0), g - 1.000001);
    int32_t i = (int32_t)u, j = (int32_t)v;
    double fu = u - i, fv = v - j;
    double d[2] = { 0.0, 0.0 };
    for (int32_t c = 0; c < 2; ++c) {
        double d00 = eye->pos[node(i, j)][c] - eye->rest[node(i, j)][c];
        double d10 = eye->pos[node(i + 1, j)][c] - eye->rest[node(i + 1, j)][c];
        double d01 = eye->pos[node(i, j + 1)][c] - eye->rest[node(i, j + 1)][c];
        double d11 = eye->pos[node(i + 1, j + 1)][c] - eye->rest[node(i + 1, j + 1)][c];
        d[c] = (d00 * (1 - fu) + d10 * fu) * (1 - fv) + (d01 * (1 - fu) + d11 * fu) * fv;
    }
    *out_r = r + d[0];
    *out_z = z + d[1];
}

void drift__glare_scene_pose(drift__glare_scene *s, const drift__glare_eye_state *eye,
                             const drift_glare_params *p)
{
    (void)p;
    int32_t nd = 0, nl = 0;
    // Lens particles: deformed (r, z), then cylindrical -> Cartesian and orthographic
    // projection along the axis into the pupil plane (the single-plane approach, §8.3).
    for (int32_t i = 0; i < s->lens_count; ++i) {
        const drift__glare_lens_particle *q = &s->lens[i];
        double r, z;
        lens_lookup(eye, (double)q->r, (double)q->z, &r, &z);
        s->disks[nd++] = (drift__glare_disk){ (float)(r * cos((double)q->phi)),
                                              (float)(r * sin((double)q->phi)), q->radius };
    }
    // Vitreous: rotate the body by (yaw, pitch), project orthographically.
    double cy = cos(eye->pub.vitreous_angle[0]), sy = sin(eye->pub.vitreous_angle[0]);
    double cp = cos(eye->pub.vitreous_angle[1]), sp = sin(eye->pub.vitreous_angle[1]);
    for (int32_t i = 0; i < s->vitreous_count; ++i) {
        const float *v = s->vitreous[i];
        double vx = (double)v[0], vy = (double)v[1], vz = (double)v[2];
        double x = cy * vx + sy * vz, z = -sy * vx + cy * vz;
        double y = cp * vy - sp * z;
        s->disks[nd++] = (drift__glare_disk){ (float)x, (float)y, v[3] };
    }
    for (int32_t i = 0; i < s->static_count; ++i) {
        s->disks[nd++] = s->static_disks[i];
    }
    s->disk_count = nd;
    for (int32_t i = 0; i < s->grating_count; ++i) {
        const drift__glare_grating *g = &s->gratings[i];
        double r0, r1, z0, z1;
        lens_lookup(eye, (double)g->r0, (double)g->z, &r0, &z0);
        lens_lookup(eye, (double)g->r1, (double)g->z, &r1, &z1);
        double c = cos((double)g->phi), sn = sin((double)g->phi);
        s->lines[nl++] = (drift__glare_line){ (float)(r0 * c), (float)(r0 * sn), (float)(r1 * c),
                                              (float)(r1 * sn), g->width };
    }
    // Lashes hang from the lid edges into the opening.
    double top, bottom;
    drift__glare_lids(eye->pub.blink, &top, &bottom);
    for (int32_t i = 0; i < s->lash_count; ++i) {
        const drift__glare_lash *l = &s->lashes[i];
        double x0 = (double)l->x, bend = 0.02 * x0 * x0;
        double y0 = l->upper ? top + bend : bottom - bend;
        double dir = l->upper ? -1.0 : 1.0;
        double len = l->upper ? (double)l->length : 0.6 * (double)l->length;
        double x1 = x0 + len * sin((double)l->angle), y1 = y0 + dir * len * cos((double)l->angle);
        s->lines[nl++] =
            (drift__glare_line){ (float)x0, (float)y0, (float)x1, (float)y1, l->width };
    }
    s->line_count = nl;
}

// drift view [SCENE]: the interactive viewer. A thin SDL2 window over the view core
// (include/drift/view.h): it opens a window, turns SDL events into view events, and copies
// the view's framebuffer to the screen. Everything else (camera, techniques, buffers, split,
// overlay) is in the core, which the unit tests drive without a display. docs/viewer.md.
#include "cli.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SDL_MAIN_HANDLED
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/image.h"
#include "drift/image_io.h"
#include "drift/knobs.h"
#include "drift/scene_io.h"
#include "drift/view.h"

#include <SDL.h>

// Set from the SIGINT handler; frames poll it (reference passes stop early).
static atomic_bool interrupted;

static void on_sigint(int sig)
{
    (void)sig;
    atomic_store(&interrupted, true);
}

typedef struct view_options {
    const char *scene_path;
    const char *screenshot_path;
    const char *press;           // --press: view keys applied before the first frame
    const char *environment;     // --environment FILE|R,G,B
    double environment_strength; // --environment-strength X
    long width, height, threads, spp_per_frame, spp, seed, frames;
    double exposure;
    drift_hybrid_params hybrid; // techniques and knobs (drift_hybrid_params_default else)
    bool split, no_overlay, verbose;
    bool refine;            // --refine sir
    long refine_budget;     // --budget: SIR samples a frame (0: the default)
    bool temporal;          // --temporal on: reuse across frames (docs/temporal.md)
    long still_refine;      // --still-refine off|on|progressive: a still camera refines to PT
    long still_spp;         // --still-spp: path-traced samples a still frame (0: the default)
    long moving_refine;     // --moving-refine off|path|residual (temporal_settings)
    const char *edits_path; // --reflection-edits: loaded if it exists, saved by the save key
} view_options;

// The key bindings, shown by the help key in the overlay (a tab separates the columns; ASCII
// only: the overlay's font has nothing else). The first line, the effects' keys, is made from
// the technique table (effect_keys_line).
static const char other_keys_text[] =
    "Tab, Shift-Tab\tnext / previous buffer: the frame, then every plane\n"
    "Space\tsplit view: hybrid left, reference right\n"
    "[ ]\tmove the split (middle click: put it there)\n"
    "W A S D, arrows\tfly forward / left / back / right\n"
    "E Q\tup / down\n"
    "left drag\torbit about the target\n"
    "right drag\tlook around\n"
    "wheel\tdolly toward / away from the target\n"
    "+ -\texposure +/- 0.5 stops\n"
    "R, Home\treset the camera\n"
    "K, Shift-K\tnext / previous knob (every knob of --help's tables)\n"
    ". ,\tthe knob up / down\n"
    "O\toverlay on/off\n"
    "H, F1\tthis help on/off\n"
    "Ctrl-click\tedit: a constraint at a reflective point\n"
    "Ctrl-left drag\tits red handle (slide the reflection)\n"
    "Ctrl-right drag\tits green handle (what it reflects)\n"
    "G, Shift-G\tadd a region around it / remove the last\n"
    "J\tadd a geodesic region around it (along its mesh)\n"
    "U, Ctrl-Z\tundo the last edit\n"
    "P, Ctrl-S\tsave the edit file (--reflection-edits)\n"
    "Esc\tquit";

// "1 2 3 4\tnext shadows / reflections / dof / indirect technique\n" and the other keys.
static const char *help_text(void)
{
    static char text[2048];
    if (text[0]) {
        return text;
    }
    size_t len = 0;
    for (int e = 0; e < DRIFT_EFFECT_COUNT && e < 9; ++e) {
        len += (size_t)snprintf(text + len, sizeof text - len, "%s%d", e ? " " : "", e + 1);
    }
    len += (size_t)snprintf(text + len, sizeof text - len, "\tnext ");
    for (int e = 0; e < DRIFT_EFFECT_COUNT && e < 9; ++e) {
        len += (size_t)snprintf(text + len, sizeof text - len, "%s%s", e ? " / " : "",
                                drift_effect_name((drift_effect)e));
    }
    snprintf(text + len, sizeof text - len, " technique\n%s", other_keys_text);
    return text;
}

// The key table for a terminal: the first column padded instead of tabbed.
static void print_keys(FILE *out)
{
    const char *line = help_text();
    while (*line) {
        const char *end = strchr(line, '\n');
        int len = end ? (int)(end - line) : (int)strlen(line);
        const char *tab = memchr(line, '\t', (size_t)len);
        int key_len = tab ? (int)(tab - line) : len;
        fprintf(out, "  %-18.*s%.*s\n", key_len, line, tab ? len - key_len - 1 : 0,
                tab ? tab + 1 : "");
        line = end ? end + 1 : line + len;
    }
}

static void print_more_help(FILE *out)
{
    fprintf(out, "\nkeys:\n");
    print_keys(out);
}

static bool parse_press(const char *cmd, const char *flag, const char *v, void *field);

#define O view_options
static const cli_option view_table[] = {
    CLI_SECTION("options:", 0),
    CLI_INT("--width", "W", O, width, 1, 16384,
            "window and image size (default: the scene camera's)"),
    CLI_INT("--height", "H", O, height, 1, 16384, "window and image size"),
    CLI_INT("--threads", "T", O, threads, 0, 256, "worker threads (default: all cores)"),
    CLI_TECHNIQUES("NAME", O, hybrid),
    CLI_INT("--spp", "N", O, spp, 1, 1 << 20,
            "samples a pixel for `reference` techniques (default 4)"),
    CLI_INT("--spp-per-frame", "N", O, spp_per_frame, 1, 1 << 16,
            "reference samples added per frame in split view (default 1)"),
    CLI_INT("--seed", "S", O, seed, 0, UINT32_MAX, "the reference's seed (default 0)"),
    CLI_FLAG("--split", O, split, "start in split view"),
    CLI_CUSTOM("--refine", "sir", O, refine, cli_parse_refine,
               "smart image refinement while the camera stands; the\n"
               "planes add error.combined (heat map) and refine.mask"),
    CLI_INT("--budget", "N", O, refine_budget, 1, 1L << 30,
            "SIR samples a frame (default 16384; docs/sir.md)"),
    CLI_CHOICE("--temporal", "off|on", O, temporal, "off|on",
               "reuse across frames: a still camera converges, a moving one\n"
               "reprojects its history (default on; docs/temporal.md; not with\n"
               "--refine, which turns it off)"),
    CLI_CHOICE("--still-refine", "on|off|progressive", O, still_refine, "off|on|progressive",
               "--temporal on, a still camera: each frame adds a path-traced\n"
               "sample a pixel, denoised and blended in where its error is the\n"
               "lower; progressive: once still, no more hybrid frames, every\n"
               "frame path-traces --still-spp samples and the hybrid fades out\n"
               "by sample count (default progressive; docs/temporal.md)"),
    CLI_INT("--still-spp", "N", O, still_spp, 1, 1 << 16,
            "path-traced samples a pixel each still frame adds (default 1; 4\n"
            "with --still-refine progressive)"),
    CLI_CHOICE("--moving-refine", "off|path|residual", O, moving_refine, "off|path|residual",
               "--temporal on: every frame adds a path-traced sample a pixel,\n"
               "reprojected with the history, filtered and blended in where its\n"
               "error is the lower (default off; docs/temporal.md)"),
    CLI_NUMBER("--exposure", "STOPS", O, exposure, -64.0, 64.0, "display exposure (default 0)"),
    CLI_STRING("--environment", "FILE|R,G,B", O, environment,
               "replace the scene's environment by a lat-long image (.hdr, .exr)\n"
               "or a constant colour (glTF files carry no world; docs/scene-format.md)"),
    CLI_NUMBER("--environment-strength", "X", O, environment_strength, 0.0, 1e9,
               "multiplies --environment (default 1)"),
    CLI_FLAG("--no-overlay", O, no_overlay, "start without the text overlay"),
    CLI_CUSTOM("--press", "KEY,KEY,...", O, press, parse_press,
               "apply view keys before the first frame, by their names\n"
               "(shadows, next-buffer, split, help, ...: docs/viewer.md;\n"
               "pick@X:Y red@X:Y green@X:Y edit reflections at pixel X, Y)"),
    CLI_STRING("--reflection-edits", "FILE.json", O, edits_path,
               "edit reflections: loaded when it exists, written by P\n"
               "(pick@X:Y, red@X:Y, green@X:Y in --press; docs/reflection-editing.md)"),
    CLI_INT("--frames", "N", O, frames, 1, 1L << 30,
            "render N frames, then exit (default: until closed)"),
    CLI_STRING("--screenshot", "FILE.png", O, screenshot_path,
               "after the last frame (--frames, default 1) save the\n"
               "window's contents and print on stdout one line:\n"
               "'wrote FILE (WxH, N frames, SOURCE): mean M, C colours'\n"
               "(M the mean 8-bit value / 255, C the distinct RGB colours)"),
    CLI_FLAG("--verbose", O, verbose, "more log output"),
    CLI_SECTION("technique knobs, each family's table (include/drift/knobs.h):", 0),
    CLI_KNOBS(O, hybrid),
};
#undef O

static const cli_command view_command = {
    .name = "view",
    .usage = "usage: drift view [SCENE] [options]\n"
             "\n"
             "Opens a window on SCENE (default: the built-in Cornell box) rendered by the hybrid\n"
             "frame renderer, with a camera you move, a technique per effect you switch, every\n"
             "buffer of the frame, a split view against the progressive reference path tracer\n"
             "and the milliseconds of each pass on screen.\n"
             "\n",
    .more_help = print_more_help,
    .epilogue =
        "\n"
        "A window needs a display: without one, run it under a virtual X server\n"
        "(xvfb-run -a drift view ...). Exit status: 0 success, 1 failure (no display, scene,\n"
        "render), 2 usage error, 130 interrupted.\n",
    CLI_TABLE(view_table),
    CLI_POSITIONAL("SCENE", view_options, scene_path, 1),
    .help_column = 27,
};

// Checks (view == NULL) or applies a comma-separated list of view key names.
static bool parse_keys(const char *list, drift_view *view)
{
    const char *p = list;
    while (*p) {
        size_t len = strcspn(p, ",");
        // pick@X:Y, red@X:Y, green@X:Y: the editing mouse events at pixel (X, Y).
        static const char *const edit_events[3] = { "pick@", "red@", "green@" };
        static const drift_view_event_type edit_types[3] = { DRIFT_VIEW_EVENT_EDIT_PICK,
                                                             DRIFT_VIEW_EVENT_EDIT_RED,
                                                             DRIFT_VIEW_EVENT_EDIT_GREEN };
        bool edit = false;
        for (int k = 0; k < 3 && !edit; ++k) {
            size_t n = strlen(edit_events[k]);
            if (len > n && strncmp(p, edit_events[k], n) == 0) {
                char at[64] = "";
                snprintf(at, sizeof at, "%.*s", (int)(len - n), p + n);
                double x, y;
                char tail;
                if (sscanf(at, "%lf:%lf%c", &x, &y, &tail) != 2 || !(x >= 0.0) || !(y >= 0.0) ||
                    x > 1e6 || y > 1e6) {
                    fprintf(stderr, "drift view: --press: '%.*s' expects %sX:Y in pixels\n",
                            (int)len, p, edit_events[k]);
                    return false;
                }
                if (view) {
                    drift_view_handle_event(view, &(drift_view_event){ .type = edit_types[k],
                                                                       .x = (float)x + 0.5f,
                                                                       .y = (float)y + 0.5f });
                }
                edit = true;
            }
        }
        if (edit) {
            p += len;
            p += *p == ',';
            continue;
        }
        drift_view_key key = DRIFT_VIEW_KEY_NONE;
        for (int k = 1; k < DRIFT_VIEW_KEY_COUNT; ++k) {
            const char *name = drift_view_key_name((drift_view_key)k);
            if (strlen(name) == len && strncmp(name, p, len) == 0) {
                key = (drift_view_key)k;
            }
        }
        if (key == DRIFT_VIEW_KEY_NONE) {
            fprintf(stderr, "drift view: --press: unknown key '%.*s' (keys:", (int)len, p);
            for (int k = 1; k < DRIFT_VIEW_KEY_COUNT; ++k) {
                fprintf(stderr, " %s", drift_view_key_name((drift_view_key)k));
            }
            fprintf(stderr, ")\n");
            return false;
        }
        if (view) {
            drift_view_handle_event(
                view, &(drift_view_event){ .type = DRIFT_VIEW_EVENT_KEY, .key = key });
        }
        p += len;
        p += *p == ',';
    }
    return true;
}

// --press: checked here, applied once the view exists.
static bool parse_press(const char *cmd, const char *flag, const char *v, void *field)
{
    (void)cmd;
    (void)flag;
    *(const char **)field = v;
    return parse_keys(v, NULL);
}

// Returns 0 on success, 2 on a usage error (message printed), -1 after --help.
static int parse_options(int argc, char **argv, view_options *o)
{
    *o = (view_options){ .spp = 4,
                         .spp_per_frame = 1,
                         .hybrid = drift_hybrid_params_default(),
                         .temporal = true,
                         .still_refine = 2 };
    cli_knobs_unset(&o->hybrid);
    int status = cli_parse(&view_command, argc, argv, o, NULL);
    if (status != CLI_PARSED) {
        return status;
    }
    cli_knobs_finish(&o->hybrid, o->refine);
    if (o->screenshot_path) {
        size_t len = strlen(o->screenshot_path);
        if (len < 5 || strcmp(o->screenshot_path + len - 4, ".png") != 0) {
            fprintf(stderr, "drift view: --screenshot must name a .png file, got '%s'\n",
                    o->screenshot_path);
            return 2;
        }
        if (o->frames == 0) {
            o->frames = 1;
        }
    }
    return 0;
}

// --- SDL EVENTS -> VIEW EVENTS ---

static drift_view_key key_of(SDL_Keycode sym, bool shift)
{
    // 1, 2, 3, ...: the next technique of each effect, in the technique table's order.
    if (sym >= SDLK_1 && sym <= SDLK_9 && sym - SDLK_1 < DRIFT_EFFECT_COUNT) {
        return drift_view_key_of_effect((drift_effect)(sym - SDLK_1));
    }
    switch (sym) {
    case SDLK_TAB:
        return shift ? DRIFT_VIEW_KEY_PREV_BUFFER : DRIFT_VIEW_KEY_NEXT_BUFFER;
    case SDLK_SPACE:
        return DRIFT_VIEW_KEY_SPLIT;
    case SDLK_LEFTBRACKET:
        return DRIFT_VIEW_KEY_SPLIT_LEFT;
    case SDLK_RIGHTBRACKET:
        return DRIFT_VIEW_KEY_SPLIT_RIGHT;
    case SDLK_w:
    case SDLK_UP:
        return DRIFT_VIEW_KEY_FORWARD;
    case SDLK_s:
    case SDLK_DOWN:
        return DRIFT_VIEW_KEY_BACK;
    case SDLK_a:
    case SDLK_LEFT:
        return DRIFT_VIEW_KEY_LEFT;
    case SDLK_d:
    case SDLK_RIGHT:
        return DRIFT_VIEW_KEY_RIGHT;
    case SDLK_e:
    case SDLK_PAGEUP:
        return DRIFT_VIEW_KEY_UP;
    case SDLK_q:
    case SDLK_PAGEDOWN:
        return DRIFT_VIEW_KEY_DOWN;
    case SDLK_PLUS:
    case SDLK_EQUALS:
    case SDLK_KP_PLUS:
        return DRIFT_VIEW_KEY_EXPOSURE_UP;
    case SDLK_MINUS:
    case SDLK_KP_MINUS:
        return DRIFT_VIEW_KEY_EXPOSURE_DOWN;
    case SDLK_r:
    case SDLK_HOME:
        return DRIFT_VIEW_KEY_RESET_CAMERA;
    case SDLK_o:
        return DRIFT_VIEW_KEY_OVERLAY;
    case SDLK_h:
    case SDLK_F1:
        return DRIFT_VIEW_KEY_HELP;
    case SDLK_g:
        return shift ? DRIFT_VIEW_KEY_EDIT_UNREGION : DRIFT_VIEW_KEY_EDIT_REGION;
    case SDLK_j:
        return DRIFT_VIEW_KEY_EDIT_GEODESIC_REGION;
    case SDLK_u:
    case SDLK_z:
        return DRIFT_VIEW_KEY_EDIT_UNDO;
    case SDLK_p:
        return DRIFT_VIEW_KEY_EDIT_SAVE;
    case SDLK_k:
        return shift ? DRIFT_VIEW_KEY_KNOB_PREV : DRIFT_VIEW_KEY_KNOB_NEXT;
    case SDLK_PERIOD:
        return DRIFT_VIEW_KEY_KNOB_UP;
    case SDLK_COMMA:
        return DRIFT_VIEW_KEY_KNOB_DOWN;
    default:
        return DRIFT_VIEW_KEY_NONE;
    }
}

// Keys that toggle or cycle act once per press; moving and exposure follow auto-repeat.
static bool key_repeats(drift_view_key key)
{
    return (key >= DRIFT_VIEW_KEY_FORWARD && key <= DRIFT_VIEW_KEY_EXPOSURE_DOWN) ||
           key == DRIFT_VIEW_KEY_SPLIT_LEFT || key == DRIFT_VIEW_KEY_SPLIT_RIGHT;
}

// Applies one SDL event to the view. Returns true when the view changed; *quit on close.
static bool handle_sdl_event(drift_view *view, const SDL_Event *e, bool *quit)
{
    drift_view_event ev = { .type = DRIFT_VIEW_EVENT_COUNT };
    switch (e->type) {
    case SDL_QUIT:
        *quit = true;
        return false;
    case SDL_KEYDOWN: {
        if (e->key.keysym.sym == SDLK_ESCAPE) {
            *quit = true;
            return false;
        }
        bool shift = (e->key.keysym.mod & KMOD_SHIFT) != 0;
        drift_view_key key = key_of(e->key.keysym.sym, shift);
        if (key == DRIFT_VIEW_KEY_NONE || (e->key.repeat && !key_repeats(key))) {
            return false;
        }
        ev = (drift_view_event){ .type = DRIFT_VIEW_EVENT_KEY, .key = key };
        break;
    }
    case SDL_MOUSEMOTION:
        if ((SDL_GetModState() & KMOD_CTRL) &&
            (e->motion.state & (SDL_BUTTON_LMASK | SDL_BUTTON_RMASK))) {
            ev = (drift_view_event){ .type = (e->motion.state & SDL_BUTTON_LMASK)
                                                 ? DRIFT_VIEW_EVENT_EDIT_RED
                                                 : DRIFT_VIEW_EVENT_EDIT_GREEN,
                                     .x = (float)e->motion.x + 0.5f,
                                     .y = (float)e->motion.y + 0.5f };
            break;
        }
        if (e->motion.state & SDL_BUTTON_LMASK) {
            ev.type = DRIFT_VIEW_EVENT_ORBIT;
        } else if (e->motion.state & SDL_BUTTON_RMASK) {
            ev.type = DRIFT_VIEW_EVENT_LOOK;
        } else if (e->motion.state & SDL_BUTTON_MMASK) {
            ev = (drift_view_event){ .type = DRIFT_VIEW_EVENT_SPLIT_AT, .x = (float)e->motion.x };
            break;
        } else {
            return false;
        }
        ev.dx = (float)e->motion.xrel;
        ev.dy = (float)e->motion.yrel;
        break;
    case SDL_MOUSEBUTTONDOWN:
        if (e->button.button == SDL_BUTTON_LEFT && (SDL_GetModState() & KMOD_CTRL)) {
            ev = (drift_view_event){ .type = DRIFT_VIEW_EVENT_EDIT_PICK,
                                     .x = (float)e->button.x + 0.5f,
                                     .y = (float)e->button.y + 0.5f };
            break;
        }
        if (e->button.button != SDL_BUTTON_MIDDLE) {
            return false;
        }
        ev = (drift_view_event){ .type = DRIFT_VIEW_EVENT_SPLIT_AT, .x = (float)e->button.x };
        break;
    case SDL_MOUSEWHEEL:
        ev = (drift_view_event){
            .type = DRIFT_VIEW_EVENT_DOLLY,
            .dy = (float)(e->wheel.direction == SDL_MOUSEWHEEL_FLIPPED ? -e->wheel.y : e->wheel.y)
        };
        break;
    case SDL_WINDOWEVENT:
        // Exposed or restored: present again, nothing to re-render.
        return false;
    default:
        return false;
    }
    return drift_view_handle_event(view, &ev);
}

// --- SCREENSHOT ---

typedef struct window {
    SDL_Window *window;
    SDL_Renderer *renderer;
    SDL_Texture *texture;
} window;

static void window_destroy(window *w)
{
    if (w->texture) {
        SDL_DestroyTexture(w->texture);
    }
    if (w->renderer) {
        SDL_DestroyRenderer(w->renderer);
    }
    if (w->window) {
        SDL_DestroyWindow(w->window);
    }
    *w = (window){ 0 };
}

// Copies the framebuffer to the back buffer; the caller presents it (or reads it back first).
static bool window_draw(window *w, const uint8_t *pixels, int width)
{
    if (SDL_UpdateTexture(w->texture, NULL, pixels, width * 3) != 0 ||
        SDL_RenderClear(w->renderer) != 0 ||
        SDL_RenderCopy(w->renderer, w->texture, NULL, NULL) != 0) {
        fprintf(stderr, "drift view: cannot draw the frame: %s\n", SDL_GetError());
        return false;
    }
    return true;
}

// Saves width*height RGB8 pixels as a PNG and prints the one-line summary --help documents.
static int save_screenshot(drift_context *ctx, const char *path, const uint8_t *rgb, int width,
                           int height, long frames, const char *source)
{
    drift_image image;
    drift_result r = drift_image_create(ctx, width, height, 3, &image);
    uint8_t *seen = calloc((size_t)1 << 21, 1); // one bit per 24-bit colour
    if (r != DRIFT_OK || !seen) {
        fprintf(stderr, "drift view: out of memory for the screenshot\n");
        drift_image_destroy(ctx, &image);
        free(seen);
        return 1;
    }
    double sum = 0.0;
    uint64_t colours = 0;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const uint8_t *p = rgb + ((size_t)y * (size_t)width + (size_t)x) * 3u;
            float *q = drift_image_pixel(&image, x, y);
            for (int c = 0; c < 3; ++c) {
                // PNG saving applies the sRGB curve again: store linear values it maps back
                // to these bytes.
                q[c] = drift_srgb_to_linear((float)p[c] / 255.0f);
                sum += p[c];
            }
            uint32_t key = (uint32_t)p[0] << 16 | (uint32_t)p[1] << 8 | p[2];
            if (!(seen[key >> 3] & (1u << (key & 7)))) {
                seen[key >> 3] |= (uint8_t)(1u << (key & 7));
                colours += 1;
            }
        }
    }
    free(seen);
    r = drift_image_save_png(ctx, path, &image, NULL);
    drift_image_destroy(ctx, &image);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift view: cannot write %s: %s\n", path, drift_result_string(r));
        return 1;
    }
    double mean = sum / (255.0 * 3.0 * (double)width * (double)height);
    printf("wrote %s (%dx%d, %ld frames, %s): mean %.4f, %llu colours\n", path, width, height,
           frames, source, mean, (unsigned long long)colours);
    return 0;
}

// Reads the window back (what is on screen) and saves it; falls back to the view's
// framebuffer, saying so, where the renderer cannot read pixels.
static int take_screenshot(drift_context *ctx, window *w, const drift_view *view,
                           const view_options *o)
{
    drift_view_state s = drift_view_get_state(view);
    int width = 0, height = 0;
    uint8_t *pixels = NULL;
    if (SDL_GetRendererOutputSize(w->renderer, &width, &height) == 0 && width > 0 && height > 0) {
        pixels = malloc((size_t)width * (size_t)height * 3u);
    }
    if (pixels &&
        SDL_RenderReadPixels(w->renderer, NULL, SDL_PIXELFORMAT_RGB24, pixels, width * 3) == 0) {
        int status =
            save_screenshot(ctx, o->screenshot_path, pixels, width, height, o->frames, "window");
        free(pixels);
        return status;
    }
    fprintf(stderr, "drift view: cannot read the window back (%s); saving the framebuffer\n",
            SDL_GetError());
    free(pixels);
    return save_screenshot(ctx, o->screenshot_path, drift_view_pixels(view), s.width, s.height,
                           o->frames, "framebuffer");
}

// --- MAIN LOOP ---

static int open_window(window *w, const char *title, int width, int height)
{
    w->window = SDL_CreateWindow(title, SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED, width,
                                 height, SDL_WINDOW_SHOWN);
    if (!w->window) {
        fprintf(stderr, "drift view: cannot open a %dx%d window: %s\n", width, height,
                SDL_GetError());
        return 1;
    }
    w->renderer = SDL_CreateRenderer(w->window, -1, 0);
    if (!w->renderer) {
        w->renderer = SDL_CreateRenderer(w->window, -1, SDL_RENDERER_SOFTWARE);
    }
    if (w->renderer) {
        w->texture = SDL_CreateTexture(w->renderer, SDL_PIXELFORMAT_RGB24,
                                       SDL_TEXTUREACCESS_STREAMING, width, height);
    }
    if (!w->renderer || !w->texture) {
        fprintf(stderr, "drift view: cannot create a renderer for the window: %s\n",
                SDL_GetError());
        return 1;
    }
    return 0;
}

static int run_loop(drift_context *ctx, drift_view *view, window *w, const view_options *o)
{
    drift_view_state s = drift_view_get_state(view);
    bool quit = false, dirty = true;
    long frames_done = 0;
    while (!quit && !atomic_load(&interrupted)) {
        // Idle (nothing changed, no reference converging): sleep until an event comes.
        SDL_Event e;
        bool busy = dirty || s.split || o->frames > 0;
        if (!busy && SDL_WaitEventTimeout(&e, 250)) {
            dirty |= handle_sdl_event(view, &e, &quit);
        }
        while (SDL_PollEvent(&e)) {
            dirty |= handle_sdl_event(view, &e, &quit);
        }
        if (quit) {
            break;
        }
        bool render = dirty || s.split || o->frames > 0;
        if (render) {
            drift_result r = drift_view_frame(view, &interrupted);
            if (r == DRIFT_ERR_CANCELLED) {
                break;
            }
            if (r != DRIFT_OK) {
                fprintf(stderr, "drift view: cannot render a frame: %s\n", drift_result_string(r));
                return 1;
            }
            frames_done += 1;
            dirty = false;
            s = drift_view_get_state(view);
        }
        if (!window_draw(w, drift_view_pixels(view), s.width)) {
            return 1;
        }
        if (o->frames > 0 && frames_done >= o->frames) {
            // Read back before presenting: after a present the back buffer is undefined.
            int status = o->screenshot_path ? take_screenshot(ctx, w, view, o) : 0;
            SDL_RenderPresent(w->renderer);
            return status;
        }
        SDL_RenderPresent(w->renderer);
    }
    if (atomic_load(&interrupted)) {
        fprintf(stderr, "drift view: interrupted\n");
        return 130;
    }
    return 0;
}

int drift_cmd_view(int argc, char **argv)
{
    view_options o;
    int status = parse_options(argc, argv, &o);
    if (status != 0) {
        return status < 0 ? 0 : status;
    }
    // The window first: without a display there is no point in loading the scene.
    SDL_SetHint(SDL_HINT_NO_SIGNAL_HANDLERS, "1");
    bool video = SDL_Init(SDL_INIT_VIDEO) == 0;
    // Without a display SDL may fall back to its windowless "offscreen" driver: that is no
    // window either, unless asked for by name (SDL_VIDEODRIVER=offscreen).
    const char *driver = video ? SDL_GetCurrentVideoDriver() : NULL;
    const char *requested = SDL_getenv("SDL_VIDEODRIVER");
    bool windowless = driver && (strcmp(driver, "offscreen") == 0 || strcmp(driver, "dummy") == 0);
    if (!video || (windowless && !(requested && *requested))) {
        fprintf(stderr,
                "drift view: cannot open a window: %s\n"
                "drift view: is there a display (DISPLAY or WAYLAND_DISPLAY)? Without one, run\n"
                "            it under a virtual X server: xvfb-run -a drift view ...\n",
                video ? "no display (only SDL's windowless video driver is available)"
                      : SDL_GetError());
        SDL_Quit();
        return 1;
    }
    signal(SIGINT, on_sigint);

    drift_view *view = NULL;
    window w = { 0 };
    int exit_code = 1;
    cli_session session;
    if (!cli_session_open(&(cli_session_desc){ .cmd = "view",
                                               .scene_path = o.scene_path,
                                               .environment = o.environment,
                                               .environment_strength = o.environment_strength,
                                               .threads = (int)o.threads,
                                               .verbose = o.verbose },
                          &session)) {
        goto done;
    }
    drift_context *ctx = session.ctx;
    const char *scene_path = session.scene_path;
    drift_hybrid_params params = o.hybrid;
    params.spp = (uint32_t)o.spp;
    drift_result r = drift_view_create(
        ctx, session.scene, session.accel,
        &(drift_view_desc){ .width = (int32_t)o.width,
                            .height = (int32_t)o.height,
                            .hybrid = params,
                            .spp_per_frame = (uint32_t)o.spp_per_frame,
                            .seed = (uint32_t)o.seed,
                            .exposure_stops = (float)o.exposure,
                            .split = o.split,
                            .hide_overlay = o.no_overlay,
                            .help_text = help_text(),
                            .refine = o.refine,
                            .refine_budget = (uint32_t)o.refine_budget,
                            .temporal = o.temporal,
                            .temporal_settings = { .no_still_refine = o.still_refine == 0,
                                                   .still_keeps_hybrid = o.still_refine == 1,
                                                   .still_spp = (uint32_t)o.still_spp,
                                                   .moving_refine = (int32_t)o.moving_refine },
                            .reflection_edits_path = o.edits_path },
        &view);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift view: %s\n", drift_result_string(r));
        goto done;
    }
    if (o.press) {
        parse_keys(o.press, view);
    }
    drift_view_state s = drift_view_get_state(view);
    char title[512];
    const char *base = strrchr(scene_path, '/');
    snprintf(title, sizeof(title), "drift view: %s (H: keys)", base ? base + 1 : scene_path);
    if (open_window(&w, title, s.width, s.height) != 0) {
        goto done;
    }
    exit_code = run_loop(ctx, view, &w, &o);

done:
    window_destroy(&w);
    drift_view_destroy(view);
    cli_session_close(&session);
    SDL_Quit();
    return exit_code;
}

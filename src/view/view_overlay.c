// The viewer's text overlay: a table of lines and tab-separated cells drawn with
// stb_easy_font's quads on a dark box, top left of the framebuffer.
#include "drift/knobs.h"
#include "view/view_internal.h"

#include <math.h>
#include <stb/stb_easy_font.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define OVERLAY_TEXT_MAX DRIFT_VIEW_OVERLAY_TEXT_MAX

// stb_easy_font indexes a table by (char - 32): keep printable ASCII, tabs and newlines.
static void sanitize(char *text)
{
    for (char *c = text; *c; ++c) {
        if (*c != '\n' && *c != '\t' && (*c < 32 || *c > 126)) {
            *c = '?';
        }
    }
}

#define TEXT_MAX_COLUMNS 8
#define TEXT_COLUMN_GAP  8 // font units between table columns
#define TEXT_LINE_HEIGHT 12

// Calls draw(cell, column x, line y) for every tab-separated cell of `text` in font units;
// columns line up (each as wide as its widest cell). Returns the table's size.
typedef void (*cell_func)(drift_view *view, char *cell, int32_t x, int32_t y, void *user);

static void layout_table(drift_view *view, char *text, cell_func draw, void *user,
                         int32_t *out_width, int32_t *out_height)
{
    int32_t widths[TEXT_MAX_COLUMNS] = { 0 };
    int32_t lines = 0;
    for (int pass = 0; pass < 2; ++pass) {
        char *line = text;
        lines = 0;
        while (*line) {
            char *line_end = strchr(line, '\n');
            char *next = line_end ? line_end + 1 : line + strlen(line);
            char saved_line = line_end ? *line_end : '\0';
            if (line_end) {
                *line_end = '\0';
            }
            int32_t x = 0;
            char *cell = line;
            for (int column = 0; cell; ++column) {
                char *tab = column < TEXT_MAX_COLUMNS - 1 ? strchr(cell, '\t') : NULL;
                if (tab) {
                    *tab = '\0';
                }
                if (pass == 0) {
                    int32_t w = stb_easy_font_width(cell);
                    widths[column] = w > widths[column] ? w : widths[column];
                } else if (draw) {
                    draw(view, cell, x, lines * TEXT_LINE_HEIGHT, user);
                }
                x += widths[column] + TEXT_COLUMN_GAP;
                if (tab) {
                    *tab = '\t';
                }
                cell = tab ? tab + 1 : NULL;
            }
            if (line_end) {
                *line_end = saved_line;
            }
            lines += 1;
            line = next;
        }
    }
    int32_t width = 0;
    for (int c = 0; c < TEXT_MAX_COLUMNS; ++c) {
        width += widths[c] > 0 ? widths[c] + (c ? TEXT_COLUMN_GAP : 0) : 0;
    }
    *out_width = width;
    *out_height = lines * TEXT_LINE_HEIGHT - 2; // the last line has no gap below it
}

typedef struct text_origin {
    int32_t x, y, scale;
} text_origin;

// Rasterizes stb_easy_font's quads for one cell into the framebuffer.
static void draw_cell(drift_view *view, char *cell, int32_t x, int32_t y, void *user)
{
    const text_origin *o = user;
    const uint8_t ink[3] = { 235, 235, 235 };
    int quads = stb_easy_font_print((float)x, (float)y, cell, NULL, view->text_vertices,
                                    VIEW_TEXT_VERTEX_BYTES);
    const float *v = view->text_vertices; // 4 floats a vertex: x, y, z, colour bytes
    const float s = (float)o->scale;
    for (int q = 0; q < quads; ++q, v += 16) {
        // Vertices 0 and 2 are opposite corners of the quad.
        float qx0 = fminf(v[0], v[8]), qx1 = fmaxf(v[0], v[8]);
        float qy0 = fminf(v[1], v[9]), qy1 = fmaxf(v[1], v[9]);
        drift_view_blend_rect(view, o->x + (int32_t)lrintf(qx0 * s),
                              o->y + (int32_t)lrintf(qy0 * s), o->x + (int32_t)lrintf(qx1 * s),
                              o->y + (int32_t)lrintf(qy1 * s), ink, 1.0f);
    }
}

// Draws `text` (lines separated by '\n', table cells by '\t') at (x, y) on a dark box,
// `scale` pixels a font unit.
static void draw_text(drift_view *view, char *text, int32_t x, int32_t y, int32_t scale)
{
    sanitize(text);
    int32_t w = 0, h = 0;
    layout_table(view, text, NULL, NULL, &w, &h);
    const int32_t pad = 4 * scale;
    const uint8_t dark[3] = { 0, 0, 0 };
    drift_view_blend_rect(view, x - pad, y - pad, x + w * scale + pad, y + h * scale + pad, dark,
                          0.7f);
    text_origin origin = { x, y, scale };
    layout_table(view, text, draw_cell, &origin, &w, &h);
}

// Appends printf-style text to buf (capacity OVERLAY_TEXT_MAX), truncating quietly.
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static void
append(char *buf, size_t *len, const char *fmt, ...)
{
    if (*len >= OVERLAY_TEXT_MAX - 1) {
        return;
    }
    va_list args;
    va_start(args, fmt);
    int n = vsnprintf(buf + *len, OVERLAY_TEXT_MAX - *len, fmt, args);
    va_end(args);
    if (n > 0) {
        *len += (size_t)n < OVERLAY_TEXT_MAX - *len ? (size_t)n : OVERLAY_TEXT_MAX - 1 - *len;
    }
}

static const char *technique_of(const drift_hybrid_params *p, drift_effect effect)
{
    const char *name = drift_technique_name(effect, drift_hybrid_params_technique(p, effect));
    return name ? name : "?";
}

// The frame's stages, two a line in columns 0-3 (they add up to the frame: none is left out),
// and beside them, one a line in columns 4-5, its counts: what each chosen technique's family
// reports it did (drift_hybrid_stats_count), the same as --stats and the CLI's pass table.
#define OVERLAY_MAX_STAGES (DRIFT_EFFECT_COUNT + 8)

static void append_frame_table(char *text, size_t *len, const drift_hybrid_stats *stats)
{
    const char *stage_names[OVERLAY_MAX_STAGES];
    double stage_ms[OVERLAY_MAX_STAGES];
    uint32_t stages = 0;
    const char *name;
    double value;
    for (uint32_t k = 0;
         stages < OVERLAY_MAX_STAGES && drift_hybrid_stats_stage(stats, k, &name, &value); ++k) {
        if (value > 0.0) { // a stage that did not run this frame is left out
            stage_names[stages] = name;
            stage_ms[stages++] = value;
        }
    }
    uint32_t counts = 0;
    while (drift_hybrid_stats_count(stats, counts, &name, &value)) {
        ++counts;
    }
    uint32_t stage_lines = (stages + 1) / 2;
    uint32_t lines = stage_lines > counts ? stage_lines : counts;
    for (uint32_t line = 0; line < lines; ++line) {
        for (uint32_t j = 0; j < 2; ++j) {
            uint32_t i = 2 * line + j;
            if (i < stages) {
                append(text, len, "%s%s\t%.2f ms", j ? "\t" : "", stage_names[i], stage_ms[i]);
            } else {
                append(text, len, "%s\t", j ? "\t" : "");
            }
        }
        if (line < counts && drift_hybrid_stats_count(stats, line, &name, &value)) {
            append(text, len, "\t%s\t%.6g", name, value);
        }
        append(text, len, "\n");
    }
}

size_t drift_view_overlay_text(const drift_view *view, char *text, size_t capacity)
{
    char buf[OVERLAY_TEXT_MAX];
    size_t len = 0;
    buf[0] = '\0';
    if (view->help && view->help_text) {
        append(buf, &len, "%s", view->help_text);
    } else {
        for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
            append(buf, &len, "%s\t%s\n", drift_effect_name((drift_effect)e),
                   technique_of(&view->params, (drift_effect)e));
        }
        {
            const drift_knob *k = drift_knob_get(view->knob);
            char value[64];
            drift_knob_format(k, drift_knob_value(&view->params, view->knob), value, sizeof value);
            append(buf, &len, "knob %d/%d\t%s %s\n", view->knob + 1, drift_knob_count(), k->name,
                   value);
        }
        append(buf, &len, "buffer\t%s\n", view->buffer_name);
        append(buf, &len, "exposure\t%+.1f stops\n", (double)view->exposure_stops);
        if (drift_reflection_edits_constraint_count(view->edits) > 0 ||
            drift_reflection_edits_region_count(view->edits) > 0) {
            append(buf, &len, "edits\t%u constraints, %u regions\n",
                   drift_reflection_edits_constraint_count(view->edits),
                   drift_reflection_edits_region_count(view->edits));
        }
        if (view->split) {
            append(buf, &len, "pt reference\t%u spp\n",
                   view->reference ? drift_pt_sample_count(view->reference) : 0u);
        } else {
            append(buf, &len, "pt reference\toff\n");
        }
        drift_hybrid_stats stats = drift_hybrid_get_stats(view->hybrid);
        append(buf, &len, "frame\t%.2f ms\n", stats.frame_ms);
        append_frame_table(buf, &len, &stats);
    }
    while (len > 0 && buf[len - 1] == '\n') {
        buf[--len] = '\0';
    }
    if (text && capacity > 0) {
        size_t n = len < capacity - 1 ? len : capacity - 1;
        memcpy(text, buf, n);
        text[n] = '\0';
    }
    return len;
}

void drift_view_draw_overlay(drift_view *view)
{
    char text[OVERLAY_TEXT_MAX];
    drift_view_overlay_text(view, text, sizeof text);
    int32_t scale = view->width >= 1280 ? 2 : 1;
    draw_text(view, text, 6 * scale, 6 * scale, scale);
}

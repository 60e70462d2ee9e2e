// A PLY file checked before assimp reads it. assimp's PLY reader reserves what the header
// declares before reading any data, loads a file cut short without a word, and names no line
// in what it reports. This walks the header and every element the header declares: an ASCII
// file's errors name the file and line (a line with too few or too many values, a value that
// is not a number, the file ending before the last element); a binary file's name the byte
// offset and the element.
#include "scene_io_internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum {
    PLY_MAX_ELEMENTS = 16,
    PLY_MAX_PROPERTIES = 64
};

typedef struct ply_property {
    int size;       // bytes of a scalar, or of each list item
    int count_size; // bytes of a list's count; 0 for a scalar
    bool count_signed;
    bool face_indices; // a face's vertex_indices (or vertex_index): a count of 0 is refused
} ply_property;

typedef struct ply_element {
    char name[64];
    unsigned long long count;
    int property_count;
    ply_property properties[PLY_MAX_PROPERTIES];
} ply_element;

typedef struct ply_reader {
    drift_context *ctx;
    const char *path;
    const char *data;
    size_t size;
    size_t pos;
    int line; // of the text at pos (ASCII and the header)
    bool binary, big_endian;
    int element_count;
    ply_element elements[PLY_MAX_ELEMENTS];
} ply_reader;

__attribute__((format(printf, 3, 4))) static drift_result
ply_error_at_line(const ply_reader *r, int line, const char *fmt, ...)
{
    char message[512];
    va_list args;
    va_start(args, fmt);
    vsnprintf(message, sizeof message, fmt, args);
    va_end(args);
    drift_log(r->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, r->path, line, "%s", message);
    return DRIFT_ERR_PARSE;
}

// The byte size of a PLY type name, or 0 for an unknown one.
static int ply_type_size(const char *type, bool *is_signed)
{
    static const struct {
        const char *name;
        int size;
        bool is_signed;
    } types[] = { { "char", 1, true },    { "uchar", 1, false },  { "short", 2, true },
                  { "ushort", 2, false }, { "int", 4, true },     { "uint", 4, false },
                  { "float", 4, true },   { "double", 8, true },  { "int8", 1, true },
                  { "uint8", 1, false },  { "int16", 2, true },   { "uint16", 2, false },
                  { "int32", 4, true },   { "uint32", 4, false }, { "float32", 4, true },
                  { "float64", 8, true } };

    for (size_t i = 0; i < sizeof types / sizeof types[0]; ++i) {
        if (strcmp(type, types[i].name) == 0) {
            if (is_signed) {
                *is_signed = types[i].is_signed;
            }
            return types[i].size;
        }
    }
    return 0;
}

// Copies the line at r->pos (without its newline or a carriage return) into buf and steps
// past it; false at the end of the data.
static bool ply_next_line(ply_reader *r, char *buf, size_t buf_size, bool *ended_by_newline)
{
    if (r->pos >= r->size) {
        return false;
    }
    const char *line = r->data + r->pos;
    const char *end = memchr(line, '\n', r->size - r->pos);
    size_t len = end ? (size_t)(end - line) : r->size - r->pos;
    r->pos += len + (end ? 1 : 0);
    *ended_by_newline = end != NULL;
    if (len > 0 && line[len - 1] == '\r') {
        --len;
    }
    size_t n = len < buf_size - 1 ? len : buf_size - 1;
    memcpy(buf, line, n);
    buf[n] = '\0';
    return true;
}

static drift_result ply_read_header(ply_reader *r)
{
    char line[512];
    bool newline;
    r->line = 0;
    bool have_format = false;
    for (size_t start = r->pos; ply_next_line(r, line, sizeof line, &newline); start = r->pos) {
        ++r->line;
        // A header is printable text: assimp splits its lines on other control bytes too (a
        // vertical tab in "property float\vnz"), disagrees with the data's layout and aborts
        // in its triangulation (fuzz_scene_ply).
        for (size_t i = start; i < r->pos; ++i) {
            unsigned char ch = (unsigned char)r->data[i];
            if ((ch < 0x20 && ch != '\t' && ch != '\r' && ch != '\n') || ch > 0x7e) {
                return ply_error_at_line(r, r->line,
                                         "the PLY header has a byte 0x%02x that is not printable "
                                         "text",
                                         ch);
            }
        }
        char word[32] = "", a[64] = "", b[64] = "", c[64] = "", d[64] = "";
        int n = sscanf(line, "%31s %63s %63s %63s %63s", word, a, b, c, d);
        if (r->line == 1) {
            if (strcmp(word, "ply") != 0 || n != 1) {
                return ply_error_at_line(r, 1, "not a PLY file: it must begin with 'ply'");
            }
            continue;
        }
        if (n <= 0 || strcmp(word, "comment") == 0 || strcmp(word, "obj_info") == 0) {
            continue;
        }
        if (strcmp(word, "end_header") == 0) {
            if (!have_format) {
                return ply_error_at_line(r, r->line, "the PLY header has no 'format' line");
            }
            return DRIFT_OK;
        }
        if (strcmp(word, "format") == 0) {
            if (n != 3 || (strcmp(a, "ascii") != 0 && strcmp(a, "binary_little_endian") != 0 &&
                           strcmp(a, "binary_big_endian") != 0)) {
                return ply_error_at_line(r, r->line,
                                         "unknown PLY format '%s' (ascii, binary_little_endian "
                                         "or binary_big_endian)",
                                         a);
            }
            have_format = true;
            r->binary = strcmp(a, "ascii") != 0;
            r->big_endian = strcmp(a, "binary_big_endian") == 0;
        } else if (strcmp(word, "element") == 0) {
            char *end = NULL;
            unsigned long long count = strtoull(b, &end, 10);
            if (n != 3 || end == b || *end != '\0' || b[0] == '-') {
                return ply_error_at_line(
                    r, r->line, "an element line is 'element NAME COUNT'; got '%s %s'", a, b);
            }
            if (r->element_count == PLY_MAX_ELEMENTS) {
                // More than any mesh needs; assimp hung on such headers.
                return ply_error_at_line(r, r->line, "more than %d elements in a PLY header",
                                         PLY_MAX_ELEMENTS);
            }
            ply_element *e = &r->elements[r->element_count++];
            snprintf(e->name, sizeof e->name, "%s", a);
            e->count = count;
            e->property_count = 0;
        } else if (strcmp(word, "property") == 0) {
            if (r->element_count == 0) {
                return ply_error_at_line(r, r->line, "a property before any element");
            }
            ply_element *e = &r->elements[r->element_count - 1];
            ply_property p = { 0 };
            bool is_list = strcmp(a, "list") == 0;
            if (is_list) {
                p.count_size = ply_type_size(b, &p.count_signed);
                p.size = ply_type_size(c, NULL);
                if (n != 5 || p.count_size == 0 || p.size == 0) {
                    return ply_error_at_line(r, r->line,
                                             "a list property is 'property list COUNT_TYPE "
                                             "ITEM_TYPE NAME'; got types '%s' and '%s'",
                                             b, c);
                }
            } else {
                p.size = ply_type_size(a, NULL);
                if (n != 3 || p.size == 0) {
                    return ply_error_at_line(r, r->line,
                                             "a property is 'property TYPE NAME'; '%s' is not "
                                             "a PLY type",
                                             a);
                }
            }
            if (e->property_count == PLY_MAX_PROPERTIES) {
                return ply_error_at_line(r, r->line, "more than %d properties in element '%s'",
                                         PLY_MAX_PROPERTIES, e->name);
            }
            p.face_indices = is_list && strcmp(e->name, "face") == 0 &&
                             (strcmp(d, "vertex_indices") == 0 || strcmp(d, "vertex_index") == 0);
            e->properties[e->property_count++] = p;
        } else {
            return ply_error_at_line(r, r->line, "unknown PLY header line '%s'", word);
        }
    }
    return ply_error_at_line(r, r->line + 1, "the PLY header has no 'end_header' line");
}

// Each element's line: its scalars and lists, one value each and a count then that many.
static drift_result ply_check_ascii(ply_reader *r)
{
    for (int ei = 0; ei < r->element_count; ++ei) {
        const ply_element *e = &r->elements[ei];
        for (unsigned long long k = 0; k < e->count && e->property_count > 0; ++k) {
            // Blank lines between elements are skipped, as assimp does.
            const char *text = r->data + r->pos;
            const char *stop = r->data + r->size;
            while (text < stop &&
                   (*text == '\n' || *text == '\r' || *text == ' ' || *text == '\t')) {
                r->line += *text == '\n';
                ++text;
            }
            r->pos = (size_t)(text - r->data);
            char element[96];
            snprintf(element, sizeof element, "'%s' %llu of %llu", e->name, k + 1, e->count);
            if (r->pos >= r->size) {
                return ply_error_at_line(r, r->line + 1,
                                         "the file ends before element %s (cut short?)", element);
            }
            const char *end = memchr(text, '\n', r->size - r->pos);
            const char *line_end = end ? end : stop;
            int expected = 0, got = 0;
            const char *t = text;
            for (int pi = 0; pi < e->property_count; ++pi) {
                const ply_property *p = &e->properties[pi];
                long items = 1;
                for (long item = -(p->count_size ? 1 : 0); item < items; ++item) {
                    ++expected;
                    while (t < line_end && (*t == ' ' || *t == '\t' || *t == '\r')) {
                        ++t;
                    }
                    if (t >= line_end) {
                        continue; // counted as missing below
                    }
                    char value[64];
                    size_t len = 0;
                    while (t < line_end && *t != ' ' && *t != '\t' && *t != '\r') {
                        if (*t == '\0') { // text: a NUL would end the number unseen
                            return ply_error_at_line(
                                r, r->line + 1, "a NUL byte in an ASCII PLY (element %s)", element);
                        }
                        if (len < sizeof value - 1) {
                            value[len++] = *t;
                        }
                        ++t;
                    }
                    value[len] = '\0';
                    ++got;
                    char *after = NULL;
                    double v = strtod(value, &after);
                    if (after == value || *after != '\0') {
                        return ply_error_at_line(
                            r, r->line + 1, "'%s' is not a number (element %s)", value, element);
                    }
                    if (item < 0) {
                        if (!(v >= 0.0 && v <= 1e6) || v != (double)(long)v) {
                            return ply_error_at_line(r, r->line + 1,
                                                     "a list count must be a whole number "
                                                     "from 0 to 10^6, not '%s' (element %s)",
                                                     value, element);
                        }
                        items = (long)v;
                        // assimp's triangulation aborts on a face of 1 or 2 (fuzz_scene_ply).
                        if (items < 3 && p->face_indices) {
                            return ply_error_at_line(
                                r, r->line + 1,
                                "a face with %ld vertex indices, fewer than 3 (element %s)", items,
                                element);
                        }
                    }
                }
            }
            while (t < line_end && (*t == ' ' || *t == '\t' || *t == '\r')) {
                ++t;
            }
            if (got < expected || t < line_end) {
                char counts[160];
                snprintf(counts, sizeof counts, "%s%d values, element %s needs %d",
                         t < line_end ? "more than " : "", got, element, expected);
                return ply_error_at_line(r, r->line + 1, "this line has %s%s", counts,
                                         end ? "" : " (the file is cut mid-line?)");
            }
            r->pos = end ? (size_t)(end - r->data) + 1 : r->size;
            r->line += end ? 1 : 0;
        }
    }
    return DRIFT_OK;
}

static unsigned long long ply_read_count(const ply_reader *r, const ply_property *p, bool *negative)
{
    const unsigned char *b = (const unsigned char *)r->data + r->pos;
    unsigned long long v = 0;
    for (int i = 0; i < p->count_size; ++i) {
        int at = r->big_endian ? i : p->count_size - 1 - i;
        v = (v << 8) | b[at];
    }
    *negative = p->count_signed && (b[r->big_endian ? 0 : p->count_size - 1] & 0x80) != 0;
    return v;
}

static drift_result ply_cut_binary(const ply_reader *r, const ply_element *e, unsigned long long k)
{
    drift_log(r->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, r->path, 0,
              "the file ends at byte %zu, inside '%s' element %llu of %llu (cut short?)", r->size,
              e->name, k + 1, e->count);
    return DRIFT_ERR_PARSE;
}

static drift_result ply_check_binary(ply_reader *r)
{
    for (int ei = 0; ei < r->element_count; ++ei) {
        const ply_element *e = &r->elements[ei];
        for (unsigned long long k = 0; k < e->count && e->property_count > 0; ++k) {
            for (int pi = 0; pi < e->property_count; ++pi) {
                const ply_property *p = &e->properties[pi];
                unsigned long long items = 1;
                if (p->count_size) {
                    if (r->size - r->pos < (size_t)p->count_size) {
                        return ply_cut_binary(r, e, k);
                    }
                    bool negative;
                    items = ply_read_count(r, p, &negative);
                    if (items < 3 && p->face_indices) {
                        drift_log(r->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, r->path, 0,
                                  "byte %zu: a face with %llu vertex indices, fewer than 3 ('%s' "
                                  "element %llu of %llu)",
                                  r->pos, items, e->name, k + 1, e->count);
                        return DRIFT_ERR_PARSE;
                    }
                    if (negative || items > 1000000) {
                        drift_log(r->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, r->path, 0,
                                  "byte %zu: a list count below 0 or over 10^6 in '%s' element "
                                  "%llu of %llu",
                                  r->pos, e->name, k + 1, e->count);
                        return DRIFT_ERR_PARSE;
                    }
                    r->pos += (size_t)p->count_size;
                }
                unsigned long long bytes = items * (unsigned long long)p->size;
                if (bytes > r->size - r->pos) {
                    return ply_cut_binary(r, e, k);
                }
                r->pos += (size_t)bytes;
            }
        }
    }
    return DRIFT_OK;
}

drift_result drift__ply_check(drift_context *ctx, const char *path, const char *data, size_t size)
{
    ply_reader *r = drift_alloc(ctx, sizeof *r);
    if (!r) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    *r = (ply_reader){ .ctx = ctx, .path = path, .data = data, .size = size };
    drift_result res = ply_read_header(r);
    if (res == DRIFT_OK) {
        res = r->binary ? ply_check_binary(r) : ply_check_ascii(r);
    }
    drift_free(ctx, r);
    return res;
}

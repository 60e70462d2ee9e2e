// The scene-format reference (docs/reference/scene-formats.md, `drift --formats-markdown`),
// printed from the tables the readers use: the loaders' registry (scene_formats.c), the JSON
// key table (scene_json_keys.c), the glTF extensions (scene_gltf.c), the OBJ/MTL statements
// (scene_obj.c) and the Mitsuba plugins (scene_mitsuba3.c).
#include "drift/scene_io.h"
#include "scene_io_internal.h"

#include <string.h>

// A table cell: '|' escaped so a row keeps its columns; "" as a blank.
static void cell(FILE *out, const char *text)
{
    fputs("| ", out);
    for (const char *c = text; *c; ++c) {
        if (*c == '|') {
            fputc('\\', out);
        }
        fputc(*c, out);
    }
    fputc(' ', out);
}

static void rows(FILE *out, const char *heading, const char *intro, const char *name_column,
                 const drift__format_row *table, size_t count)
{
    fprintf(out, "## %s\n\n%s\n\n| %s | drift |\n|---|---|\n", heading, intro, name_column);
    for (size_t i = 0; i < count; ++i) {
        fputs("| `", out);
        fputs(table[i].name, out);
        fputs("` ", out);
        cell(out, table[i].what);
        fputs("|\n", out);
    }
    fputc('\n', out);
}

void drift_scene_formats_markdown(FILE *out)
{
    fputs("## File formats\n\nThe loaders' registry (`drift_scene_format_get`): a file is read by "
          "its extension.\n\n| extension | also .gz | mesh file | what |\n|---|---|---|---|\n",
          out);
    for (int i = 0; i < drift_scene_format_count(); ++i) {
        const drift_scene_format *f = drift_scene_format_get(i);
        fprintf(out, "| `.%s` | %s | %s ", f->extension, f->gz ? "yes" : "no",
                f->mesh ? "yes" : "no");
        cell(out, f->summary);
        fputs("|\n", out);
    }
    fputs("\n## JSON scene file keys\n\nEvery key of every object of a `.json` scene file and of a "
          "camera-views file (`drift bench sir --views`). The reader warns about a key that is "
          "not listed for its object (`comment` is allowed everywhere); a duplicate key is an "
          "error. A light's keys depend on its `type`.\n",
          out);
    const char *object = "";
    for (size_t i = 0; i < drift__json_key_count; ++i) {
        const drift__json_key *k = &drift__json_keys[i];
        if (strcmp(k->object, object) != 0) {
            object = k->object;
            fprintf(out, "\n### %s\n\n| key | type | default | meaning |\n|---|---|---|---|\n",
                    object);
        }
        fprintf(out, "| `%s` ", k->key);
        cell(out, k->type);
        cell(out, k->def);
        cell(out, k->meaning);
        fputs("|\n", out);
    }
    fputc('\n', out);
    rows(out, "glTF extensions",
         "The extensions drift reads (besides the core glTF 2.0 that assimp reads); any other "
         "entry of `extensionsUsed` is a warning naming it.",
         "extension", drift__gltf_extensions, drift__gltf_extension_count);
    rows(out, "OBJ and MTL statements",
         "What drift reads itself beside assimp's OBJ/MTL reader (which reads `v`, `vt`, `vn`, "
         "`f`, `usemtl`).",
         "statement", drift__obj_statements, drift__obj_statement_count);
    rows(out, "Mitsuba plugins",
         "The elements and plugin types of a Mitsuba 0.6 or 3 `.xml` scene that drift reads "
         "(element, then types).",
         "element type", drift__mitsuba_plugins, drift__mitsuba_plugin_count);
}

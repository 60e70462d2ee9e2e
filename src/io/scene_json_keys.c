// The keys of drift's JSON scene and camera-views files, one row per key of each object: the
// reader warns about every key of an object that is not in its rows (scene_json.c's
// check_keys), and docs/reference/scene-formats.md prints them (drift --formats-markdown). A new
// key is a row here and its read in scene_json.c.
#include "scene_io_internal.h"

#include <string.h>

const drift__json_key drift__json_keys[] = {
    // The scene file's top level.
    { "scene", "version", "number", "1", "format version; any other is an error" },
    { "scene", "camera", "object", "none", "the camera (below); absent: a mesh file's camera" },
    { "scene", "materials", "object", "none", "named materials: name → material (below)" },
    { "scene", "meshes", "array", "[]", "mesh files to import, each a mesh entry (below)" },
    { "scene", "lights", "array", "[]", "lights, each by its `type` (below)" },
    { "scene", "environment", "object", "black", "constant colour or lat-long map (below)" },
    // "camera"
    { "camera", "position", "vec3, required", "", "eye point" },
    { "camera", "target", "vec3, required", "", "point looked at (not `position`)" },
    { "camera", "up", "vec3", "[0, 1, 0]", "up direction" },
    { "camera", "fov_y", "number, degrees", "45", "full vertical field of view, in (0, 179]" },
    { "camera", "aperture_radius", "number ≥ 0", "0", "thin-lens radius; 0 is a pinhole" },
    { "camera", "focus_distance", "number ≥ 0", "0", "distance in focus; 0: the target's" },
    { "camera", "width", "whole number", "512", "default image width, 1..32768" },
    { "camera", "height", "whole number", "512", "default image height, 1..32768" },
    // "materials": NAME → material
    { "material", "type", "string", "\"diffuse\"", "`diffuse`, `glossy`, `mirror` or `ggx`" },
    { "material", "diffuse", "colour", "0.8 (0 for glossy)",
      "Lambertian albedo; ggx: base colour" },
    { "material", "specular", "colour", "required for glossy; 1 for mirror",
      "glossy or mirror reflectance" },
    { "material", "exponent", "number", "required for glossy", "normalized-Phong exponent" },
    { "material", "emission", "colour", "0", "emitted radiance: the mesh becomes a light" },
    { "material", "diffuse_texture", "path", "none", "image multiplying `diffuse`" },
    { "material", "diffuse_roughness", "number in [0, 1]", "none (Lambert)",
      "Burley's diffuse of this roughness" },
    { "material", "roughness", "number in [0, 1]", "0.5", "ggx: perceptual roughness, α = r²" },
    { "material", "metallic", "number in [0, 1]", "0", "ggx: conductor fraction" },
    { "material", "transmission", "number in [0, 1]", "0", "ggx: refracting fraction" },
    { "material", "ior", "number in [1, 10]", "1.5", "ggx: index of refraction" },
    { "material", "metal", "string", "none", "ggx: measured conductor Au, Ag, Cu or Al" },
    { "material", "edge_tint", "colour", "0 (Schlick)", "ggx: Gulbrandsen edge tint" },
    { "material", "thin", "boolean", "false", "ggx: thin-walled sheet" },
    { "material", "clearcoat", "number in [0, 1]", "0", "ggx: clear coat weight (IOR 1.5)" },
    { "material", "clearcoat_roughness", "number in [0, 1]", "0",
      "ggx: the coat's perceptual roughness" },
    { "material", "opacity", "number in [0, 1]", "1",
      "any type: below 1, rays pass with probability 1 − opacity" },
    { "material", "opacity_texture", "path", "none",
      "any type: image whose alpha (else grey) multiplies opacity" },
    { "material", "alpha_cutoff", "number in [0, 1]", "none",
      "any type: a cut-out, there where opacity ≥ cutoff" },
    // "meshes": [mesh entry]
    { "mesh", "path", "path, required", "", "mesh file (.obj, .gltf, .glb, .ply, optionally .gz)" },
    { "mesh", "material", "string", "the file's", "material name replacing every one of the file" },
    { "mesh", "transform", "object", "identity", "placed after the file's own (below)" },
    { "mesh", "camera", "string", "the first", "glTF: the file's camera, by name or index" },
    // a mesh entry's "transform"
    { "transform", "translate", "vec3", "[0, 0, 0]", "applied last" },
    { "transform", "rotate", "object", "none", "`axis` (vec3) and `degrees` (number)" },
    { "transform", "scale", "number or vec3", "1", "applied first; non-zero" },
    { "transform", "matrix", "16 numbers", "none",
      "row-major affine matrix, instead of the others" },
    { "transform.rotate", "axis", "vec3, required", "", "rotation axis" },
    { "transform.rotate", "degrees", "number, required", "", "counter-clockwise down the axis" },
    // "lights": [light], by type
    { "light point", "type", "string", "", "`point`" },
    { "light point", "position", "vec3, required", "", "position" },
    { "light point", "intensity", "colour, required", "", "W/sr" },
    { "light spot", "type", "string", "", "`spot`" },
    { "light spot", "position", "vec3, required", "", "position" },
    { "light spot", "direction", "vec3, required", "", "cone axis" },
    { "light spot", "intensity", "colour, required", "", "W/sr" },
    { "light spot", "outer_angle", "degrees, required", "", "cone half angle, 0..180" },
    { "light spot", "inner_angle", "degrees", "0", "full-intensity half angle, ≤ outer" },
    { "light directional", "type", "string", "", "`directional`" },
    { "light directional", "direction", "vec3, required", "", "the way the light travels" },
    { "light directional", "irradiance", "colour, required", "", "W/m²" },
    { "light quad", "type", "string", "", "`quad`" },
    { "light quad", "corner", "vec3, required", "", "one corner" },
    { "light quad", "edge_u", "vec3, required", "", "first edge from the corner" },
    { "light quad", "edge_v", "vec3, required", "", "second edge; emits along u × v" },
    { "light quad", "radiance", "colour, required", "", "W/(m² sr)" },
    { "light disk", "type", "string", "", "`disk`" },
    { "light disk", "center", "vec3, required", "", "centre" },
    { "light disk", "normal", "vec3, required", "", "the side it emits to" },
    { "light disk", "radius", "number, required", "", "radius" },
    { "light disk", "radiance", "colour, required", "", "W/(m² sr)" },
    { "light sphere", "type", "string", "", "`sphere`" },
    { "light sphere", "center", "vec3, required", "", "centre" },
    { "light sphere", "radius", "number, required", "", "radius; emits outward" },
    { "light sphere", "radiance", "colour, required", "", "W/(m² sr)" },
    // "environment"
    { "environment", "color", "colour", "none", "constant radiance from every direction" },
    { "environment", "map", "path", "none", "HDR lat-long image (not with `color`)" },
    { "environment", "multiplier", "colour", "1", "scales `map`" },
    // Camera views files (drift bench sir --views)
    { "views file", "views", "array, required", "", "1 to 16 views (below)" },
    { "view", "name", "string, required", "", "1–63 letters, digits, `_`, `-`: names outputs" },
    { "view", "position", "vec3", "the scene's", "replaces the camera's position" },
    { "view", "target", "vec3", "the scene's", "replaces the camera's target" },
    { "view", "fov_y", "number, degrees", "the scene's", "vertical field of view, 0.1–179" },
    { "view", "aperture_radius", "number ≥ 0", "the scene's", "thin-lens radius" },
};

const size_t drift__json_key_count = sizeof drift__json_keys / sizeof *drift__json_keys;

bool drift__json_key_known(const char *object, const char *key)
{
    if (strcmp(key, "comment") == 0) { // allowed in every object
        return true;
    }
    for (size_t i = 0; i < drift__json_key_count; ++i) {
        if (strcmp(drift__json_keys[i].object, object) == 0 &&
            strcmp(drift__json_keys[i].key, key) == 0) {
            return true;
        }
    }
    return false;
}

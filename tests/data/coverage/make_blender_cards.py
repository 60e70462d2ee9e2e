# The Blender scene of tests/cli/test_coverage_cycles.sh, run by make_reference.sh: four
# foliage cards whose leaf texture's alpha is clipped (Blender blend mode CLIP at 0.5: glTF
# alphaMode MASK), a blue veil of alpha 0.4 (blend mode BLEND), a sphere, a floor and a wall,
# a sun and a point light; exported with Blender's glTF exporter as cards_blender.glb (the
# texture inside). Usage: blender -b --factory-startup -noaudio --python make_blender_cards.py
#                         -- OUT_DIR
import math
import sys

import bpy
import numpy as np

out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene

# The leaf texture: 64 x 64 RGBA, four ellipses of alpha 1 on alpha 0, green with stripes.
N = 64
yy, xx = np.mgrid[0:N, 0:N] / N
alpha = np.zeros((N, N), np.float32)
for cy in (0.25, 0.75):
    for cx in (0.25, 0.75):
        alpha = np.maximum(alpha, (((xx - cx) / 0.22) ** 2 + ((yy - cy) / 0.12) ** 2 < 1))
rgba = np.zeros((N, N, 4), np.float32)
rgba[..., 0] = 0.15
rgba[..., 1] = 0.55 + 0.2 * np.sin(xx * 40) ** 2
rgba[..., 2] = 0.1
rgba[..., 3] = alpha
leaf_image = bpy.data.images.new("leaf", N, N, alpha=True)
leaf_image.pixels = rgba.ravel()
leaf_image.pack()


def principled(name, color, roughness):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    b = m.node_tree.nodes["Principled BSDF"]
    b.inputs["Base Color"].default_value = (*color, 1)
    b.inputs["Roughness"].default_value = roughness
    return m, b


def plane(size, location, rotation, material):
    bpy.ops.mesh.primitive_plane_add(size=size, location=location, rotation=rotation)
    bpy.context.object.data.materials.append(material)


ground, _ = principled("Ground", (0.6, 0.6, 0.6), 0.8)
wall, _ = principled("Wall", (0.7, 0.5, 0.4), 0.7)
leaf, leaf_bsdf = principled("Leaf", (1, 1, 1), 0.6)
texture = leaf.node_tree.nodes.new("ShaderNodeTexImage")
texture.image = leaf_image
leaf.node_tree.links.new(texture.outputs["Color"], leaf_bsdf.inputs["Base Color"])
leaf.node_tree.links.new(texture.outputs["Alpha"], leaf_bsdf.inputs["Alpha"])
leaf.blend_method = 'CLIP'
leaf.alpha_threshold = 0.5
veil, veil_bsdf = principled("Veil", (0.2, 0.3, 0.9), 0.3)
veil_bsdf.inputs["Alpha"].default_value = 0.4
veil.blend_method = 'BLEND'

plane(12, (0, 0, 0), (0, 0, 0), ground)
plane(12, (0, 4, 6), (math.pi / 2, 0, 0), wall)
for i, (x, z, r) in enumerate([(-1.5, 1.2, 0.3), (0.0, 1.6, -0.2), (1.4, 1.0, 0.5),
                               (0.6, 2.4, 0.1)]):
    plane(1.6, (x, 0.5 * i - 0.5, z), (math.pi / 2 + r, 0, r), leaf)
plane(1.5, (-0.3, -1.5, 0.9), (math.pi / 2, 0, 0.4), veil)
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(-0.3, 0.3, 0.5))
bpy.ops.object.shade_smooth()
bpy.context.object.data.materials.append(wall)

bpy.ops.object.light_add(type='SUN', rotation=(math.radians(40), math.radians(-20),
                                               math.radians(30)))
bpy.context.object.data.energy = 3.0
bpy.ops.object.light_add(type='POINT', location=(2, -2, 3))
bpy.context.object.data.energy = 300
bpy.ops.object.camera_add(location=(0.5, -7, 2.5),
                          rotation=(math.radians(80), 0, math.radians(4)))
scene.camera = bpy.context.object
bpy.context.object.data.lens = 35
bpy.ops.export_scene.gltf(filepath=out + "/cards_blender.glb", export_format='GLB',
                          export_lights=True, export_cameras=True)

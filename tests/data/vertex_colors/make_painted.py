# The Blender scene of tests/cli/test_vertex_colors.sh, run by make_reference.sh: an ico
# sphere whose per-vertex colour attribute "Col" (a smooth function of position) feeds its
# Principled base colour, on a grey floor under a sun; exported by Blender's glTF exporter
# (COLOR_0) as painted.glb. Usage: blender -b --factory-startup -noaudio --python
# make_painted.py -- OUT_DIR
import math
import sys

import bpy

out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
m = bpy.data.materials.new("Painted")
m.use_nodes = True
b = m.node_tree.nodes["Principled BSDF"]
b.inputs["Roughness"].default_value = 0.6
vc = m.node_tree.nodes.new("ShaderNodeVertexColor")
vc.layer_name = "Col"
m.node_tree.links.new(vc.outputs["Color"], b.inputs["Base Color"])
g = bpy.data.materials.new("Grey")
g.use_nodes = True
g.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1)
bpy.ops.mesh.primitive_plane_add(size=10)
bpy.context.object.data.materials.append(g)
bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, radius=1, location=(0, 0, 1))
ob = bpy.context.object
ob.data.materials.append(m)
col = ob.data.color_attributes.new("Col", 'FLOAT_COLOR', 'POINT')
for i, v in enumerate(ob.data.vertices):
    col.data[i].color = (0.5 + 0.5 * math.sin(3 * v.co.x), 0.5 + 0.5 * math.cos(2 * v.co.y),
                          0.3 + 0.3 * v.co.z, 1)
bpy.ops.object.light_add(type='SUN', rotation=(math.radians(40), math.radians(-20),
                                               math.radians(30)))
bpy.context.object.data.energy = 3.0
bpy.ops.object.camera_add(location=(0, -6, 2.5), rotation=(math.radians(75), 0, 0))
sc.camera = bpy.context.object
bpy.ops.export_scene.gltf(filepath=out + "/painted.glb", export_format='GLB', export_lights=True,
                          export_cameras=True)

"""Blender: the default scene (cube, camera, point light) with a floor and an emissive quad over
the cube, exported as .glb with the exporter's default settings.

    blender --background --factory-startup --python scripts/blender-emissive-quad.py -- scene.glb

Blender 3.4 (Debian's `blender` package) was used for docs/scene-format.md; the exporter then
writes neither the camera nor the point light (its defaults), and the lamp's emission strength as
KHR_materials_emissive_strength.
"""

import sys

import bpy

out = sys.argv[sys.argv.index("--") + 1]

bpy.ops.mesh.primitive_plane_add(size=10, location=(0, 0, -1))
bpy.context.active_object.name = "Floor"

bpy.ops.mesh.primitive_plane_add(size=2, location=(0, 0, 3))
lamp = bpy.context.active_object
lamp.name = "Lamp"
lamp.rotation_euler = (3.14159265358979, 0, 0)  # facing down
material = bpy.data.materials.new("Glow")
material.use_nodes = True
bsdf = material.node_tree.nodes["Principled BSDF"]
bsdf.inputs["Emission"].default_value = (1.0, 0.9, 0.8, 1.0)
bsdf.inputs["Emission Strength"].default_value = 20.0
bsdf.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
lamp.data.materials.append(material)

bpy.ops.export_scene.gltf(filepath=out, export_format="GLB")

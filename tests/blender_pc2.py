# blender_pc2.py: run by Blender (tests/cli_blender.sh):
#   blender -b --factory-startup --python blender_pc2.py -- OBJ PC2 OUT.json FRAME...
# Imports the rest pose OBJ keeping clothsim's coordinates (no axis
# conversion), puts a Mesh Cache modifier reading the PC2 file on it, and
# writes the evaluated vertex positions at each FRAME (Blender's scene
# frame; the cache's start frame is 0, as is clothsim's first frame) into
# OUT.json, with the object's vertex count and world matrix.
import json
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:]
obj_path, pc2_path, out_path = args[:3]
frames = [int(a) for a in args[3:]]

bpy.ops.wm.read_factory_settings(use_empty=True)
# Blender is Z up; clothsim writes what it simulates. forward Y, up Z is
# Blender's own frame, so the OBJ's numbers become the vertices unchanged.
bpy.ops.wm.obj_import(filepath=obj_path, forward_axis="Y", up_axis="Z")
ob = bpy.context.selected_objects[0]
mod = ob.modifiers.new("clothsim", "MESH_CACHE")
mod.cache_format = "PC2"
mod.filepath = pc2_path
mod.time_mode = "FRAME"
mod.play_mode = "SCENE"
mod.frame_start = 0.0
mod.frame_scale = 1.0
mod.forward_axis = "POS_Y"
mod.up_axis = "POS_Z"
scene = bpy.context.scene
scene.frame_start = 0
scene.frame_end = max(frames)

result = {"object": ob.name, "vertices": len(ob.data.vertices),
          "matrix_world": [list(r) for r in ob.matrix_world], "frames": {}}
for f in frames:
    scene.frame_set(f)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = ob.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    result["frames"][str(f)] = [list(v.co) for v in mesh.vertices]
    evaluated.to_mesh_clear()
with open(out_path, "w") as fp:
    json.dump(result, fp)
print("blender_pc2: wrote", out_path)

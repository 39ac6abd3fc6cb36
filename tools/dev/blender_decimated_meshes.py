# Decimated variants of meshes, made by another simplifier than ours (issue 20: efficiency
# against the reference on non-uniform triangulations, as in "dragon 20k", "horse 20k"):
# Blender's collapse decimator (`DECIMATE`, ratio) or its planar dissolve (angle limit in
# radians), then a beauty triangulation. Debian's Blender 3.4:
#   blender -b --python tools/dev/blender_decimated_meshes.py -- OUT_DIR MESH:VALUE:NAME:MODE ...
# MODE collapse (VALUE = ratio of faces kept) or planar (VALUE = angle limit), e.g.
#   ... -- /tmp/dec horse.obj:0.2:horse_10k:collapse spot.obj:0.05:spot_planar:planar
# Run `spherekit check` on the outputs (a collapse can leave boundary loops: holes are fine).
import bpy, bmesh, sys
args = sys.argv[sys.argv.index('--') + 1:]
out = args[0]
def clear():
    bpy.ops.object.select_all(action='SELECT'); bpy.ops.object.delete()
for job in args[1:]:
    path, value, name, mode = job.split(':')
    clear()
    if path.endswith('.ply'): bpy.ops.import_mesh.ply(filepath=path)
    else: bpy.ops.wm.obj_import(filepath=path)
    o = bpy.context.selected_objects[0]; bpy.context.view_layer.objects.active = o
    m = o.modifiers.new('decimate', 'DECIMATE')
    if mode == 'collapse':
        m.ratio = float(value); m.use_collapse_triangulate = True
    elif mode == 'planar':
        m.decimate_type = 'DISSOLVE'; m.angle_limit = float(value)
    else:
        sys.exit('unknown mode ' + mode)
    bpy.ops.object.convert(target='MESH')
    me = o.data
    bm = bmesh.new(); bm.from_mesh(me)
    bmesh.ops.triangulate(bm, faces=bm.faces, quad_method='BEAUTY', ngon_method='BEAUTY')
    bm.to_mesh(me); bm.free()
    with open(f'{out}/{name}.obj', 'w') as f:
        for v in me.vertices: f.write('v %.9g %.9g %.9g\n' % tuple(v.co))
        for p in me.polygons: f.write('f ' + ' '.join(str(i + 1) for i in p.vertices) + '\n')
    print('wrote', name, len(me.vertices))

# Stress meshes of kinds the generated iso-surface sets (stress_meshes.cpp) lack, made with
# Debian's Blender 3.4 (issue 20: efficiency against the reference on meshes we do not have):
# low-poly CAD-like solids with large flat triangles and fans (bevelled box, fan-capped
# cylinder, a cone whose apex and base centre have valence 160, extruded letters, a lathed
# vase), a UV sphere stretched into a capsule (valence-128 poles), creatures from the Skin
# modifier (a biped, a seven-armed star, the biped decimated to a non-uniform triangulation)
# and a noise-displaced icosphere. Every output is a closed or single-hole genus-0 surface.
#   blender -b --python tools/dev/blender_stress_meshes.py -- OUT_DIR
# The Skin creatures keep a few unreferenced vertices: `spherekit check M --repair -o M` first.
# (Blender's modifier evaluation can differ in the last printed digit between runs.)
import bpy, bmesh, sys, math
out = sys.argv[sys.argv.index('--') + 1]
def clear():
    bpy.ops.object.select_all(action='SELECT'); bpy.ops.object.delete()
def export(name, obj=None):
    obj = obj or bpy.context.active_object
    bpy.ops.object.select_all(action='DESELECT'); obj.select_set(True); bpy.context.view_layer.objects.active = obj
    bpy.ops.object.convert(target='MESH')
    me = obj.data
    bm = bmesh.new(); bm.from_mesh(me)
    bmesh.ops.remove_doubles(bm, verts=bm.verts, dist=1e-6)
    bmesh.ops.triangulate(bm, faces=bm.faces, quad_method='BEAUTY', ngon_method='BEAUTY')
    bm.to_mesh(me); bm.free()
    with open(f'{out}/{name}.obj', 'w') as f:
        mw = obj.matrix_world
        for v in me.vertices:
            p = mw @ v.co; f.write('v %.9g %.9g %.9g\n' % (p.x, p.y, p.z))
        for p in me.polygons:
            f.write('f ' + ' '.join(str(i + 1) for i in p.vertices) + '\n')
    print('wrote', name, len(me.vertices))
def mod(obj, kind, **kw):
    m = obj.modifiers.new(kind.lower(), kind)
    for k, v in kw.items(): setattr(m, k, v)
    return m

clear(); bpy.ops.mesh.primitive_cube_add(); o = bpy.context.active_object
mod(o, 'BEVEL', width=0.15, segments=3); export('bevel_box')
clear(); bpy.ops.mesh.primitive_cylinder_add(vertices=96, depth=6, end_fill_type='TRIFAN'); export('cylinder_fan')
clear(); bpy.ops.mesh.primitive_cone_add(vertices=160, depth=3, end_fill_type='TRIFAN')
export('cone_160')
clear(); bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=48); o = bpy.context.active_object
o.scale = (1, 1, 2.5); export('uv_capsule')
# Lathe: a vase profile revolved (long thin triangles), caps closed by fans.
clear(); bm = bmesh.new()
prof = [(0.0, 0), (1.0, 0), (1.3, 0.5), (0.9, 1.5), (0.5, 2.2), (0.6, 3.0), (0.9, 3.3), (0.0, 3.3)]
vs = [bm.verts.new((x, 0, z)) for x, z in prof]
for a, b in zip(vs, vs[1:]): bm.edges.new((a, b))
me = bpy.data.meshes.new('vase'); bm.to_mesh(me); o = bpy.data.objects.new('vase', me); bpy.context.collection.objects.link(o)
bpy.context.view_layer.objects.active = o
mod(o, 'SCREW', steps=72, render_steps=72, use_merge_vertices=True, merge_threshold=1e-4)
export('vase_lathe', o)
# Extruded letters: flat n-gons triangulated into slivers.
for ch in ('S', 'E'):
    clear(); bpy.ops.object.text_add(); o = bpy.context.active_object
    o.data.body = ch; o.data.extrude = 0.1; o.data.resolution_u = 6
    export('letter_' + ch, o)
# Skin creatures: a tree skeleton thickened by the Skin modifier, subdivided once.
def creature(name, edges, pts, radii, levels=2, decimate=0):
    clear(); me = bpy.data.meshes.new(name); me.from_pydata(pts, edges, []); o = bpy.data.objects.new(name, me)
    bpy.context.collection.objects.link(o); bpy.context.view_layer.objects.active = o
    mod(o, 'SKIN')
    for i, r in enumerate(radii): o.data.skin_vertices[''].data[i].radius = (r, r)
    mod(o, 'SUBSURF', levels=levels)
    if decimate: mod(o, 'DECIMATE', ratio=decimate)
    export(name, o)
pts = [(0, 0, 0), (0, 0, 1.2), (0, 0, 1.8), (0.8, 0, 1.0), (1.6, 0, 0.6), (-0.8, 0, 1.0), (-1.6, 0, 0.6),
       (0.3, 0, -1.0), (0.3, 0, -2.2), (-0.3, 0, -1.0), (-0.3, 0, -2.2), (0, -0.6, -0.2), (0, -1.4, -0.6)]
edges = [(0, 1), (1, 2), (1, 3), (3, 4), (1, 5), (5, 6), (0, 7), (7, 8), (0, 9), (9, 10), (0, 11), (11, 12)]
R = [0.45, 0.3, 0.35, 0.12, 0.08, 0.12, 0.08, 0.15, 0.1, 0.15, 0.1, 0.1, 0.05]
creature('skin_biped', edges, pts, R)
creature('skin_biped_decim', edges, pts, R, levels=4, decimate=0.06)
pts = [(0, 0, 0)]; edges = []; radii = [0.5]
for k in range(7):
    a = 2 * math.pi * k / 7; prev = 0
    for s in range(1, 6):
        r = 0.5 + 0.45 * s
        pts.append((r * math.cos(a + 0.12 * s), r * math.sin(a + 0.12 * s), 0.15 * math.sin(s))); edges.append((prev, len(pts) - 1)); prev = len(pts) - 1
        radii.append(0.16 * (1 - 0.16 * s))
creature('skin_star', edges, pts, radii)
# Bumpy blob: icosphere displaced by a noise texture (large amplitude).
clear(); bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=6); o = bpy.context.active_object
t = bpy.data.textures.new('n', 'CLOUDS'); t.noise_scale = 0.45
mod(o, 'DISPLACE', texture=t, strength=0.6); export('noise_blob')

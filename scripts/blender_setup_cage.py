"""Builds the Blender setup of a SphereKit Catmull-Clark cage + displacement texture and saves it.

    blender -b -P scripts/blender_setup_cage.py -- CAGE.obj DISP.exr OUT.blend
        [--vector | --scalar] [--levels N] [--quality Q] [--export-obj EVALUATED.obj]

CAGE.obj and DISP.exr are what `spherekit convert --cage N --cage-tile T` writes (NAME_cage.obj,
NAME_disp.exr). The scene gets one object, the cage, with two modifiers, exactly the setup the
README describes:
  1. Subdivision Surface: Catmull-Clark, N levels (default: from the texture's tile T = 2^N + 1,
     so that every subdivided vertex lands on a texel centre and reads a stored sample),
     "Use Limit Surface" on, UV Smooth "None" (every cage quad is its own UV chart and its UVs
     must stay bilinear in the quad's parameter; "All" would move the chart corners);
  2. Displace: an Image texture of DISP.exr (colour space Non-Color, interpolation on, extension
     Extend, CLAMP OFF: Blender clamps negative texture values to 0 otherwise), texture
     coordinates UV, mid level 0, strength 1; direction Normal for a scalar texture (displacement
     along the vertex normal) or RGB to XYZ in Local space for a vector texture.
The kind (scalar / vector) and the tile come from the texture's header (SphereKit's
`displacement` and `tile` attributes); --vector / --scalar / --levels override them. The image is
packed into OUT.blend, so the .blend is self-contained.
--export-obj also writes the evaluated (subdivided + displaced) mesh as an OBJ in the object's
own coordinates, i.e. the cage's frame (no axis conversion), for measurement against the
original mesh, e.g. by SphereKit's tests.
Tested with Debian 12's Blender 3.4 (Python 3.11). Exit status 0 on success, 2 on bad arguments,
1 when a step fails (with one line on stderr).
"""

import math
import os
import struct
import sys


def fail(message, code=1):
    sys.stderr.write("blender_setup_cage: " + message + "\n")
    sys.stderr.flush()
    # os._exit: sys.exit inside `blender -P` is caught by Blender, which then goes on.
    os._exit(code)


def parse_args(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    opts = {"kind": None, "levels": None, "quality": 4, "export": None}
    pos = []
    i = 0
    while i < len(args):
        a = args[i]
        if a in ("-h", "--help"):
            print(__doc__)
            os._exit(0)
        elif a == "--vector":
            opts["kind"] = "vector"
        elif a == "--scalar":
            opts["kind"] = "scalar"
        elif a in ("--levels", "--quality", "--export-obj"):
            if i + 1 >= len(args):
                fail(a + " needs a value", 2)
            i += 1
            if a == "--export-obj":
                opts["export"] = args[i]
            else:
                try:
                    opts[a[2:]] = int(args[i])
                except ValueError:
                    fail(a + " needs an integer, not '" + args[i] + "'", 2)
        elif a.startswith("-"):
            fail("unknown option '" + a + "'", 2)
        else:
            pos.append(a)
        i += 1
    if len(pos) != 3:
        fail("usage: blender -b -P blender_setup_cage.py -- CAGE.obj DISP.exr OUT.blend "
             "[--vector|--scalar] [--levels N] [--quality Q] [--export-obj EVALUATED.obj]", 2)
    return pos, opts


def exr_string_attributes(path):
    """The string attributes of an OpenEXR header (the format's header is a list of
    name\\0 type\\0 size value, ended by an empty name)."""
    attrs = {}
    try:
        with open(path, "rb") as f:
            data = f.read(1 << 20)
    except OSError as e:
        fail(path + ": cannot read (" + e.strerror + ")")
    if len(data) < 8 or struct.unpack("<I", data[:4])[0] != 20000630:
        fail(path + ": not an OpenEXR file")
    pos = 8
    while pos < len(data):
        end = data.find(b"\0", pos)
        if end < 0 or end == pos:
            break
        name = data[pos:end].decode("latin-1")
        tend = data.find(b"\0", end + 1)
        if tend < 0 or tend + 5 > len(data):
            break
        kind = data[end + 1:tend].decode("latin-1")
        size = struct.unpack("<i", data[tend + 1:tend + 5])[0]
        value = data[tend + 5:tend + 5 + size]
        if kind == "string":
            attrs[name] = value.decode("utf-8", "replace")
        pos = tend + 5 + size
    return attrs


def write_obj(path, mesh):
    """The evaluated mesh as triangles: each quad split along its shorter diagonal (Blender's
    own 'shortest diagonal' rule, as SphereKit meshes its displaced surface), since a quad of a
    displaced surface is not planar and a measurement needs one surface."""
    import bmesh

    bm = bmesh.new()
    bm.from_mesh(mesh)
    bmesh.ops.triangulate(bm, faces=bm.faces[:], quad_method="SHORT_EDGE", ngon_method="BEAUTY")
    bm.verts.index_update()
    lines = ["# evaluated by blender_setup_cage.py (subdivision + displacement, quads split along the shorter "
             "diagonal), object coordinates\n"]
    lines += ["v %.9g %.9g %.9g\n" % tuple(v.co) for v in bm.verts]
    lines += ["f %d %d %d\n" % tuple(v.index + 1 for v in f.verts) for f in bm.faces]
    bm.free()
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.writelines(lines)
    os.replace(tmp, path)


def main():
    import bpy

    (cage_path, disp_path, out_path), opts = parse_args(sys.argv)
    for p in (cage_path, disp_path):
        if not os.path.isfile(p):
            fail(p + ": no such file")
    attrs = exr_string_attributes(disp_path)
    kind = opts["kind"] or attrs.get("displacement", "scalar")
    if kind not in ("scalar", "vector"):
        fail(disp_path + ": unknown displacement kind '" + kind + "'")
    levels = opts["levels"]
    if levels is None:
        tile = int(attrs.get("tile", "0") or 0)
        if tile < 2:
            fail(disp_path + ": no tile attribute (not a SphereKit displacement texture): give --levels N")
        levels = max(1, round(math.log2(tile - 1)))
    if not 0 <= levels <= 6 or not 1 <= opts["quality"] <= 10:
        fail("--levels must be 0..6 and --quality 1..10", 2)

    bpy.ops.wm.read_factory_settings(use_empty=True)
    before = set(bpy.data.objects)
    bpy.ops.wm.obj_import(filepath=os.path.abspath(cage_path))
    imported = [o for o in bpy.data.objects if o not in before and o.type == "MESH"]
    if len(imported) != 1:
        fail(cage_path + ": expected one mesh object, the OBJ importer made %d" % len(imported))
    ob = imported[0]
    me = ob.data
    if len(me.uv_layers) == 0:
        fail(cage_path + ": the cage has no texture coordinates (written by an older spherekit?)")
    for p in me.polygons:
        p.use_smooth = True

    sub = ob.modifiers.new("Subdivision", "SUBSURF")
    sub.subdivision_type = "CATMULL_CLARK"
    sub.levels = levels
    sub.render_levels = levels
    sub.use_limit_surface = True
    sub.quality = opts["quality"]
    sub.uv_smooth = "NONE"
    sub.boundary_smooth = "ALL"
    sub.use_creases = False
    sub.use_custom_normals = False

    img = bpy.data.images.load(os.path.abspath(disp_path), check_existing=False)
    img.colorspace_settings.name = "Non-Color"
    img.alpha_mode = "NONE"
    img.pack()
    tex = bpy.data.textures.new("displacement", "IMAGE")
    tex.image = img
    tex.use_clamp = False          # keep negative displacements
    tex.extension = "EXTEND"
    tex.use_interpolation = True   # bilinear between texel centres (box filter of one texel)
    tex.filter_size = 1.0
    tex.use_mipmap = False
    tex.use_alpha = False
    tex.use_calculate_alpha = False
    tex.use_flip_axis = False

    disp = ob.modifiers.new("Displace", "DISPLACE")
    disp.texture = tex
    disp.texture_coords = "UV"
    disp.uv_layer = me.uv_layers[0].name
    disp.mid_level = 0.0
    disp.strength = 1.0
    if kind == "vector":
        disp.direction = "RGB_TO_XYZ"
        disp.space = "LOCAL"
    else:
        disp.direction = "NORMAL"

    bpy.context.view_layer.objects.active = ob
    ob.select_set(True)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(out_path), check_existing=False)
    if opts["export"]:
        dg = bpy.context.evaluated_depsgraph_get()
        ev = ob.evaluated_get(dg)
        mesh = ev.to_mesh()
        write_obj(opts["export"], mesh)
        ev.to_mesh_clear()
    print("blender_setup_cage: %s (%s displacement, %d levels) -> %s" % (cage_path, kind, levels, out_path))
    sys.stdout.flush()


try:
    main()
except SystemExit:
    raise
except Exception as e:  # one line, non-zero exit: Blender itself would go on and exit 0
    fail("%s: %s" % (type(e).__name__, e))
os._exit(0)

#!/usr/bin/env python3
"""Sizes of glTF levels of detail at equal error: ours (adaptive, uniform) against gltfpack
-si -cc and gltf-transform simplify + draco, every decoded file measured by one routine
(glb2obj.mjs decodes Draco/meshopt/quantized glTF, `spherekit eval-surface` the PSNR).

  python3 tools/bench/lod_compare.py SPHEREKIT NAME MESH SPHERE MESH_AS_OBJ OUTDIR [-- CONVERT_ARGS]
  (env LOD_MODES=original,adaptive,uniform: which of our modes run)

SPHERE = collection:DIR measures member NAME of the consistent collection DIR (its levels from
`convert --collection`: original = the template member's mesh laid on every member, or the
common remesh where it folds; adaptive = the common remesh; one connectivity for all members
either way) against the peers run on MESH alone.

Our levels' position bits come from the convert report (the level files carry no quantization
extras). PEERS_FROM=PREVIOUS.json reuses the peers of an earlier run on the same mesh (only bit
counts it lacks are run), to compare versions of ours against the same peer files.

Needs the npm tools of scripts/setup_npm_tools.sh --compare (NODE_DIR, default
~/.cache/spherekit/npm-tools). Peers run at every position-bit count one of our levels uses
(their smallest size at each PSNR counts, so no level is compared against a peer at more bits
than it has). Ratio = our size / the peer's size interpolated (log size, linear in PSNR) at our
level's PSNR; null where the PSNR is outside the peer's range. Prints one JSON object."""
import json, math, os, subprocess, sys

sk, name, mesh, sphere, obj, d = sys.argv[1:7]
extra = sys.argv[8:] if len(sys.argv) > 7 and sys.argv[7] == '--' else []
N = os.environ.get('NODE_DIR', os.path.expanduser('~/.cache/spherekit/npm-tools'))
B = N + '/node_modules/.bin'
here = os.path.dirname(os.path.abspath(__file__))
env = dict(os.environ, NODE_DIR=N, NO_COLOR='1')
os.makedirs(d, exist_ok=True)

def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if r.returncode: raise SystemExit(' '.join(cmd) + '\n' + r.stderr[-2000:])
    return r.stdout

def psnr(glb):
    run(['node', here + '/glb2obj.mjs', glb, glb + '.obj'])
    return json.loads(run([sk, 'eval-surface', mesh, glb + '.obj', '--samples', '100000', '--json']))['psnr_db']


def interp(points, p):
    pts = sorted(points)
    for (p0, s0), (p1, s1) in zip(pts, pts[1:]):
        if p0 <= p <= p1 and p1 > p0:
            t = (p - p0) / (p1 - p0)
            return math.exp(math.log(s0) * (1 - t) + math.log(s1) * t)
    return None

# LOD_MODES (comma-separated, default original,adaptive,uniform) picks our modes; CONVERT_ARGS
# go to original and adaptive.
all_modes = {'original': ['--lod-mode', 'original'] + extra, 'adaptive': ['--lod-mode', 'adaptive'] + extra,
             'uniform': ['--lod-mode', 'uniform']}
want = os.environ.get('LOD_MODES', 'original,adaptive,uniform').split(',')
modes = {m: all_modes[m] for m in want}
ours, bits, connectivity = {}, set(), {}
for mode, args in modes.items():
    if sphere.startswith('collection:'):
        run([sk, 'convert', '--collection', sphere[len('collection:'):], '-o', f'{d}/{mode}_collection',
             '--lods', '4', '--quiet'] + args)
        level_file = lambda k: f'{d}/{mode}_collection/{name}_lod{k}.glb'
        report = json.load(open(f'{d}/{mode}_collection/convert_report.json'))
        levels = next(m for m in report['members'] if m['name'] == name)['lods']
        connectivity[mode] = report.get('lod_connectivity', {}).get('kind')
    else:
        run([sk, 'convert', mesh, sphere, '-o', f'{d}/{mode}.exr', '--lods', '4', '--quiet',
             '--report', f'{d}/{mode}_report.json'] + args)
        level_file = lambda k: f'{d}/{mode}_lod{k}.glb'
        levels = json.load(open(f'{d}/{mode}_report.json'))['lods']
    ours[mode] = []
    for k in range(4):
        f = level_file(k)
        b = levels[k]['quantization']['position_bits']
        bits.add(b)
        ours[mode].append({'psnr': psnr(f), 'bytes': os.path.getsize(f), 'position_bits': b})

run([B + '/gltfpack', '-i', obj, '-o', f'{d}/plain.glb', '-noq'])
peers = {'gltfpack': [], 'gltf-transform': []}
if os.environ.get('PEERS_FROM'):
    peers = json.load(open(os.environ['PEERS_FROM']))['peers']
have = {q['position_bits'] for q in peers['gltfpack']}
for pb in sorted(bits - have):
    for r in ['1', '0.5', '0.25', '0.125', '0.06', '0.03', '0.015', '0.008', '0.004', '0.002']:
        g = f'{d}/gp{pb}_{r}.glb'
        run([B + '/gltfpack', '-i', obj, '-o', g, '-cc', '-vp', str(pb)] + ([] if r == '1' else ['-si', r]))
        peers['gltfpack'].append({'psnr': psnr(g), 'bytes': os.path.getsize(g), 'position_bits': pb, 'ratio': r})
        s, t = f'{d}/gts{pb}_{r}.glb', f'{d}/gt{pb}_{r}.glb'
        if r == '1': run([B + '/gltf-transform', 'copy', f'{d}/plain.glb', s])
        else: run([B + '/gltf-transform', 'simplify', f'{d}/plain.glb', s, '--ratio', r, '--error', '0.01'])
        run([B + '/gltf-transform', 'draco', s, t, '--method', 'edgebreaker', '--quantize-position', str(pb)])
        peers['gltf-transform'].append({'psnr': psnr(t), 'bytes': os.path.getsize(t), 'position_bits': pb, 'ratio': r})

out = {'mesh': name, 'convert_args': extra, 'ours': ours, 'peers': peers, 'ratios': {}}
if connectivity: out['lod_connectivity'] = connectivity
for mode in ours:
    for peer, pts in peers.items():
        row = []
        for lvl in ours[mode]:
            # The peer's best size at this PSNR among the bit counts <= the level's.
            cands = [interp([(q['psnr'], q['bytes']) for q in pts if q['position_bits'] == pb], lvl['psnr'])
                     for pb in bits if pb <= lvl['position_bits']]
            cands = [c for c in cands if c]
            row.append(round(lvl['bytes'] / min(cands), 3) if cands else None)
        out['ratios'][mode + '/' + peer] = row
print(json.dumps(out))

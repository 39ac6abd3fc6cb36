// Stress meshes for the unconstrained stage (issue 20): shapes on which a stretch optimizer
// is easily out-done, written as OBJ files. Not part of the build; compile by hand:
//   g++ -O2 -std=c++20 -o /tmp/stress_meshes tools/dev/stress_meshes.cpp
//   /tmp/stress_meshes OUT_DIR [RES] [HOLES] [SEED COUNT]
//     (RES: grid cells across the box, default 96; HOLES: holes of the -holes variants, 0: none;
//      SEED: COUNT random shapes from that seed instead of the fixed set)
// Surfaces are the zero set of a smooth union (polynomial smooth minimum) of an ellipsoidal
// body and capsule chains (long thin limbs), extracted by marching tetrahedra (six per
// cube): the triangulation is irregular with many near-degenerate triangles, as scans and
// iso-surfaces are. Every shape is a single closed genus-0 surface; "-holes" variants have
// many small holes (the stars of vertices far apart removed).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

namespace {

struct V3 {
  double x, y, z;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
double len(V3 a) { return std::sqrt(dot(a, a)); }

struct Capsule {
  V3 a, b;
  double r;
};
struct Shape {
  std::string name;
  V3 body_radii;
  std::vector<Capsule> limbs;
  double blend;  // smooth-minimum radius
};

double capsule_sd(V3 p, const Capsule& c) {
  V3 ab = c.b - c.a;
  double t = std::clamp(dot(p - c.a, ab) / dot(ab, ab), 0.0, 1.0);
  return len(p - (c.a + t * ab)) - c.r;
}
double smin(double a, double b, double k) {
  double h = std::clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0);
  return b + (a - b) * h - k * h * (1 - h);
}
double field(const Shape& s, V3 p) {
  // Scaled ellipsoid distance (approximate; its zero set is exact).
  V3 q{p.x / s.body_radii.x, p.y / s.body_radii.y, p.z / s.body_radii.z};
  double mr = std::min({s.body_radii.x, s.body_radii.y, s.body_radii.z});
  double d = (len(q) - 1) * mr;
  for (const Capsule& c : s.limbs) d = smin(d, capsule_sd(p, c), s.blend);
  return d;
}

// A chain of capsules from `from` in direction `dir`, bending by `bend` per segment.
void limb(Shape& s, V3 from, V3 dir, double length, double r0, double r1, int segs, V3 bend) {
  V3 p = from;
  for (int i = 0; i < segs; ++i) {
    double t = (i + 0.5) / segs;
    V3 d = dir + (double(i) / segs) * bend;
    d = (1 / len(d)) * d;
    V3 q = p + (length / segs) * d;
    s.limbs.push_back({p, q, r0 + (r1 - r0) * t});
    p = q;
  }
}

std::vector<Shape> shapes() {
  std::vector<Shape> out;
  {  // A blob with eight long thin tentacles, some curling.
    Shape s{"tentacles", {0.45, 0.4, 0.35}, {}, 0.08};
    for (int i = 0; i < 8; ++i) {
      double a = 2 * M_PI * i / 8;
      V3 dir{std::cos(a), std::sin(a), -0.35};
      limb(s, {0.3 * std::cos(a), 0.3 * std::sin(a), -0.1}, dir, 1.3 + 0.1 * (i % 3), 0.07, 0.03, 6,
           {-0.5 * std::sin(a), 0.5 * std::cos(a), -0.6 * (i % 2)});
    }
    out.push_back(s);
  }
  {  // Quadruped: legs, neck and head, thin tail and ears (cow / horse stand-in).
    Shape s{"quadruped", {0.7, 0.3, 0.3}, {}, 0.06};
    for (int i = 0; i < 4; ++i) {
      double x = i < 2 ? 0.5 : -0.5, y = i % 2 ? 0.17 : -0.17;
      limb(s, {x, y, -0.1}, {0.05, 0, -1}, 0.9, 0.09, 0.05, 3, {0, 0, 0});
    }
    limb(s, {0.6, 0, 0.1}, {0.6, 0, 1}, 0.6, 0.13, 0.1, 3, {0.4, 0, -0.6});
    s.limbs.push_back({{1.05, 0, 0.62}, {1.35, 0, 0.45}, 0.12});  // head
    limb(s, {1.1, 0.08, 0.7}, {0, 0.6, 1}, 0.25, 0.035, 0.02, 2, {0, 0, 0});   // ears
    limb(s, {1.1, -0.08, 0.7}, {0, -0.6, 1}, 0.25, 0.035, 0.02, 2, {0, 0, 0});
    limb(s, {-0.7, 0, 0.1}, {-1, 0, -0.3}, 0.9, 0.03, 0.015, 5, {0, 0, -1.2});  // tail
    out.push_back(s);
  }
  {  // Standing blob: a squat body on two legs with two long arms and a thin antenna.
    Shape s{"standing", {0.35, 0.3, 0.5}, {}, 0.1};
    limb(s, {0.15, 0, -0.4}, {0.2, 0, -1}, 0.9, 0.12, 0.1, 3, {0, 0, 0});
    limb(s, {-0.15, 0, -0.4}, {-0.2, 0, -1}, 0.9, 0.12, 0.1, 3, {0, 0, 0});
    limb(s, {0.3, 0, 0.2}, {1, 0, 0.2}, 1.1, 0.07, 0.05, 4, {0, 0.5, -0.8});
    limb(s, {-0.3, 0, 0.2}, {-1, 0, 0.2}, 1.1, 0.07, 0.05, 4, {0, -0.5, -0.8});
    limb(s, {0, 0, 0.45}, {0.1, 0.1, 1}, 0.8, 0.025, 0.012, 4, {0.8, 0, 0});
    out.push_back(s);
  }
  {  // Hand: a flat palm with five fingers of two or three bending segments (fingers of scans).
    Shape s{"hand", {0.45, 0.4, 0.12}, {}, 0.05};
    for (int i = 0; i < 4; ++i) {
      double y = -0.27 + 0.18 * i;
      limb(s, {0.35, y, 0}, {1, 0.05 * (i - 1.5), 0}, 0.55 + 0.08 * (i % 3), 0.06, 0.045, 3, {0, 0, -0.5});
    }
    limb(s, {0.1, -0.35, 0}, {0.5, -1, 0}, 0.45, 0.07, 0.05, 2, {0.6, 0, -0.2});  // thumb
    limb(s, {-0.4, 0, 0}, {-1, 0, 0}, 0.3, 0.2, 0.18, 1, {0, 0, 0});              // wrist
    out.push_back(s);
  }
  {  // Biped: head on a neck, two arms with hands, two legs with feet (a human-body stand-in).
    Shape s{"biped", {0.22, 0.14, 0.4}, {}, 0.06};
    s.limbs.push_back({{0, 0, 0.42}, {0, 0, 0.55}, 0.06});   // neck
    s.limbs.push_back({{0, 0, 0.62}, {0, 0.02, 0.72}, 0.1});  // head
    for (int side = -1; side <= 1; side += 2) {
      limb(s, {0.2 * side, 0, 0.3}, {side * 1.0, 0, -0.4}, 0.75, 0.055, 0.04, 3, {0, 0.3, -0.6});
      limb(s, {0.1 * side, 0, -0.35}, {0.1 * side, 0, -1}, 0.85, 0.08, 0.055, 3, {0, 0.1, 0});
      s.limbs.push_back({{0.13 * side, 0, -1.2}, {0.13 * side, 0.18, -1.22}, 0.05});  // foot
    }
    out.push_back(s);
  }
  {  // Spiky ball: a sphere with twelve short cones along the icosahedron's vertex directions.
    Shape s{"spiky", {0.5, 0.5, 0.5}, {}, 0.04};
    const double g = (1 + std::sqrt(5.0)) / 2;
    const V3 dirs[12] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                         {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    for (const V3& d0 : dirs) {
      V3 d = (1 / len(d0)) * d0;
      limb(s, 0.4 * d, d, 0.45, 0.1, 0.02, 3, {0, 0, 0});
    }
    out.push_back(s);
  }
  {  // Disc: a flat wide body (large near-planar regions) with one thin handle.
    Shape s{"disc", {0.8, 0.8, 0.08}, {}, 0.05};
    limb(s, {0.75, 0, 0}, {1, 0, 0.3}, 0.7, 0.05, 0.035, 4, {0, 0.8, 0});
    out.push_back(s);
  }
  return out;
}

struct Mesh {
  std::vector<V3> V;
  std::vector<std::array<int, 3>> F;
};

// Marching tetrahedra on a regular grid (Kuhn decomposition: six tetrahedra sharing the
// cube diagonal, consistent across cubes), vertices on grid edges welded by edge key.
Mesh extract(const Shape& s, int res) {
  V3 lo{1e9, 1e9, 1e9}, hi{-1e9, -1e9, -1e9};
  auto grow = [&](V3 p, double r) {
    lo = {std::min(lo.x, p.x - r), std::min(lo.y, p.y - r), std::min(lo.z, p.z - r)};
    hi = {std::max(hi.x, p.x + r), std::max(hi.y, p.y + r), std::max(hi.z, p.z + r)};
  };
  grow({0, 0, 0}, std::max({s.body_radii.x, s.body_radii.y, s.body_radii.z}));
  for (const Capsule& c : s.limbs) grow(c.a, c.r), grow(c.b, c.r);
  double ext = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}) + 0.2;
  double h = ext / res;
  lo = lo - V3{0.1, 0.1, 0.1};
  int nx = int((hi.x - lo.x + 0.1) / h) + 2, ny = int((hi.y - lo.y + 0.1) / h) + 2, nz = int((hi.z - lo.z + 0.1) / h) + 2;
  auto id = [&](int i, int j, int k) { return (long long)(k * ny + j) * nx + i; };
  std::vector<double> val((size_t)nx * ny * nz);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        double f = field(s, lo + V3{i * h, j * h, k * h});
        if (f == 0) f = 1e-12;  // never exactly on the surface: a manifold result
        val[(size_t)id(i, j, k)] = f;
      }
  Mesh m;
  std::unordered_map<long long, int> edge_vertex;
  auto pos = [&](long long g) {
    int i = int(g % nx), j = int((g / nx) % ny), k = int(g / ((long long)nx * ny));
    return lo + V3{i * h, j * h, k * h};
  };
  auto vert = [&](long long a, long long b) {
    if (a > b) std::swap(a, b);
    // Grid edges of the Kuhn tetrahedra join corners that differ by one of seven offsets.
    long long key = a * 7 + (b - a == 1 ? 0 : b - a == nx ? 1 : b - a == (long long)nx * ny ? 2 : b - a == nx + 1 ? 3
                   : b - a == (long long)nx * ny + 1 ? 4 : b - a == (long long)nx * ny + nx ? 5 : 6);
    auto it = edge_vertex.find(key);
    if (it != edge_vertex.end()) return it->second;
    double fa = val[(size_t)a], fb = val[(size_t)b];
    double t = fa / (fa - fb);
    m.V.push_back(pos(a) + t * (pos(b) - pos(a)));
    edge_vertex[key] = int(m.V.size()) - 1;
    return int(m.V.size()) - 1;
  };
  // Kuhn tetrahedra: paths 0 -> 7 through the cube corners along axis permutations.
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k + 1 < nz; ++k)
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i)
        for (const auto& p : perms) {
          int c[4][3];
          c[0][0] = i, c[0][1] = j, c[0][2] = k;
          for (int t = 1; t < 4; ++t) {
            for (int d = 0; d < 3; ++d) c[t][d] = c[t - 1][d];
            c[t][p[t - 1]] += 1;
          }
          long long g[4];
          for (int t = 0; t < 4; ++t) g[t] = id(c[t][0], c[t][1], c[t][2]);
          int in[4], nin = 0, out_[4], nout = 0;
          for (int t = 0; t < 4; ++t) (val[(size_t)g[t]] < 0 ? in[nin++] : out_[nout++]) = t;
          if (nin == 0 || nin == 4) continue;
          // Faces oriented with the outward normal (from inside to outside): decide by a
          // geometric test on the produced triangle rather than by case tables.
          auto emit = [&](int a, int b, int c2) {
            if (a == b || b == c2 || a == c2) return;
            m.F.push_back({a, b, c2});
          };
          auto orient = [&](std::array<int, 3> tri, V3 inside_pt) {
            V3 n{0, 0, 0};
            V3 p0 = m.V[tri[0]], p1 = m.V[tri[1]], p2 = m.V[tri[2]];
            V3 e1 = p1 - p0, e2 = p2 - p0;
            n = {e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x};
            if (dot(n, inside_pt - p0) > 0) std::swap(tri[1], tri[2]);
            emit(tri[0], tri[1], tri[2]);
          };
          V3 ic{0, 0, 0};
          for (int t = 0; t < nin; ++t) ic = ic + (1.0 / nin) * pos(g[in[t]]);
          if (nin == 1 || nin == 3) {
            int apex = nin == 1 ? in[0] : out_[0];
            int o[3], no = 0;
            for (int t = 0; t < 4; ++t)
              if (t != apex) o[no++] = t;
            std::array<int, 3> tri{vert(g[apex], g[o[0]]), vert(g[apex], g[o[1]]), vert(g[apex], g[o[2]])};
            orient(tri, ic);
          } else {
            int a = vert(g[in[0]], g[out_[0]]), b = vert(g[in[0]], g[out_[1]]);
            int c2 = vert(g[in[1]], g[out_[1]]), d = vert(g[in[1]], g[out_[0]]);
            orient({a, b, c2}, ic);
            orient({a, c2, d}, ic);
          }
        }
  return m;
}

// Keep only the largest connected component (marching cells may leave specks) and drop
// unreferenced vertices.
Mesh largest_component(const Mesh& m) {
  std::vector<int> parent(m.V.size());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = int(i);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const auto& f : m.F) parent[find(f[0])] = find(f[1]), parent[find(f[1])] = find(f[2]);
  std::map<int, int> count;
  for (const auto& f : m.F) ++count[find(f[0])];
  int best = -1, bc = 0;
  for (auto [r, c] : count)
    if (c > bc) best = r, bc = c;
  Mesh out;
  std::vector<int> remap(m.V.size(), -1);
  for (const auto& f : m.F) {
    if (find(f[0]) != best) continue;
    std::array<int, 3> g;
    for (int k = 0; k < 3; ++k) {
      if (remap[f[k]] < 0) remap[f[k]] = int(out.V.size()), out.V.push_back(m.V[f[k]]);
      g[k] = remap[f[k]];
    }
    out.F.push_back(g);
  }
  return out;
}

// Many small holes: remove the stars of vertices at least `spacing` rings apart.
Mesh punch_holes(const Mesh& m, int holes, unsigned seed) {
  std::vector<std::vector<int>> vv(m.V.size());
  std::vector<std::vector<int>> vf(m.V.size());
  for (size_t f = 0; f < m.F.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      vf[m.F[f][k]].push_back(int(f));
      vv[m.F[f][k]].push_back(m.F[f][(k + 1) % 3]);
    }
  std::vector<char> blocked(m.V.size(), 0), drop(m.F.size(), 0);
  std::vector<char> removed_v(m.V.size(), 0);
  unsigned x = seed;
  int made = 0;
  for (int tries = 0; tries < holes * 50 && made < holes; ++tries) {
    x = x * 1664525u + 1013904223u;
    int v = int(x % m.V.size());
    if (blocked[v]) continue;
    // Block a 4-ring neighbourhood so holes stay separate (a manifold result).
    std::vector<int> frontier{v};
    blocked[v] = 1;
    for (int r = 0; r < 4; ++r) {
      std::vector<int> nxt;
      for (int a : frontier)
        for (int b : vv[a])
          if (!blocked[b]) blocked[b] = 1, nxt.push_back(b);
      frontier.swap(nxt);
    }
    for (int f : vf[v]) drop[f] = 1;
    removed_v[v] = 1;
    ++made;
  }
  Mesh out;
  std::vector<int> remap(m.V.size(), -1);
  for (size_t f = 0; f < m.F.size(); ++f) {
    if (drop[f]) continue;
    std::array<int, 3> g;
    for (int k = 0; k < 3; ++k) {
      int w = m.F[f][k];
      if (remap[w] < 0) remap[w] = int(out.V.size()), out.V.push_back(m.V[w]);
      g[k] = remap[w];
    }
    out.F.push_back(g);
  }
  return out;
}

void write_obj(const Mesh& m, const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    std::fprintf(stderr, "stress_meshes: cannot write %s\n", path.c_str());
    std::exit(1);
  }
  for (const V3& p : m.V) std::fprintf(f, "v %.9g %.9g %.9g\n", p.x, p.y, p.z);
  for (const auto& t : m.F) std::fprintf(f, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
  std::fclose(f);
  std::printf("%s V=%zu F=%zu\n", path.c_str(), m.V.size(), m.F.size());
}

// Shapes nobody tuned for: `count` random creatures from `seed` (xorshift, so the set is the
// same on every machine): an ellipsoidal body with 3-9 limbs of random direction, length,
// thickness, taper, segment count and curl, some very thin. A fresh seed is a fresh test set.
std::vector<Shape> random_shapes(unsigned seed, int count) {
  std::uint64_t x = 0x9e3779b97f4a7c15ULL ^ (static_cast<std::uint64_t>(seed) * 0xbf58476d1ce4e5b9ULL);
  auto uniform = [&](double a, double b) {
    x ^= x << 13, x ^= x >> 7, x ^= x << 17;
    return a + (b - a) * static_cast<double>(x >> 11) / 9007199254740992.0;
  };
  std::vector<Shape> out;
  for (int i = 0; i < count; ++i) {
    Shape s{"rand" + std::to_string(seed) + "_" + std::to_string(i),
            {uniform(0.25, 0.6), uniform(0.2, 0.5), uniform(0.15, 0.5)}, {}, uniform(0.03, 0.1)};
    const int limbs = static_cast<int>(uniform(3, 10));
    for (int l = 0; l < limbs; ++l) {
      const double z = uniform(-1, 1), a = uniform(0, 2 * M_PI), r = std::sqrt(1 - z * z);
      const V3 d{r * std::cos(a), r * std::sin(a), z};
      const V3 from{0.8 * s.body_radii.x * d.x, 0.8 * s.body_radii.y * d.y, 0.8 * s.body_radii.z * d.z};
      const double r0 = uniform(0.025, 0.13);
      limb(s, from, d, uniform(0.3, 1.4), r0, r0 * uniform(0.3, 1.0), static_cast<int>(uniform(1, 6)),
           {uniform(-0.8, 0.8), uniform(-0.8, 0.8), uniform(-0.8, 0.8)});
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: stress_meshes OUT_DIR [RES] [HOLES] [SEED COUNT]\n");
    return 2;
  }
  std::string dir = argv[1];
  int res = argc > 2 ? std::atoi(argv[2]) : 96;
  int holes = argc > 3 ? std::atoi(argv[3]) : 24;
  // With SEED: COUNT random shapes (random_shapes) instead of the fixed ones.
  const std::vector<Shape> set = argc > 4 ? random_shapes(static_cast<unsigned>(std::atoi(argv[4])), argc > 5 ? std::atoi(argv[5]) : 8)
                                          : shapes();
  for (const Shape& s : set) {
    Mesh m = largest_component(extract(s, res));
    write_obj(m, dir + "/" + s.name + "_r" + std::to_string(res) + ".obj");
    if (holes > 0) write_obj(punch_holes(m, holes, 12345u), dir + "/" + s.name + "_r" + std::to_string(res) + "-holes.obj");
  }
  return 0;
}

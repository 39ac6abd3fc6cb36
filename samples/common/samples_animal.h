// Internal to the sample collection: the animal-like surfaces X: S^2 -> R^3, their
// template landmarks and hole caps.
//
// Shape model. A body ellipsoid B(u) = S u (S = diag(length, width, height)) plus limbs:
//
//   X(u) = B(u) + sum_i L_i phi_i(|B(u) - B(c_i)|) t_i
//
// Limb i is a smooth bump of the body centred at template direction c_i, displaced by up
// to L_i along its own direction t_i (the pose), with profile phi = exp(-q^1.5),
// q = |B(u) - B(c_i)|^2 / r_i^2: a limb that tapers a little toward a rounded end. (The
// Gaussian exp(-q) ends in a needle point of radius r^2 / 2L ~ 0.01 that no mesh of this
// resolution triangulates well; exp(-q^2) gives a flat end above a wall so steep that
// adaptive refinement keeps halving edges across it.) Bumps are measured on the body
// surface, so a limb's footprint is round whatever the body proportions.
//
// Why this is an embedding (no self-intersection), so the samples are honest surfaces:
// the ellipsoid is one; where a bump acts, the body patch is a graph over the plane
// orthogonal to t_i (t_i . normal > 0 on the footprint; the pose ranges below keep it so
// with a wide margin), and moving a graph along t_i keeps it a graph; limb footprints
// are disjoint and their directions diverge (legs down and outward, tail back, head
// forward, ears up on the head), so limbs do not meet each other.
//
// Correspondence. Every member uses the same template directions c_i and the same
// landmark template points: members differ in proportions (S, L_i, r_i) and pose (t_i),
// never in where a feature sits on the template sphere. So "same template point" means
// "same anatomical point" for every pair of members, which is the ground truth.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "samples_tessellation.h"

namespace spherekit::samples::detail {

/// Template directions (x forward, y left, z up). Fixed for every member.
struct AnimalTemplate {
  Vec3 head = Vec3(0.80, 0, 0.60).normalized();
  Vec3 legs[4] = {Vec3(0.55, 0.45, -0.70).normalized(), Vec3(0.55, -0.45, -0.70).normalized(),
                  Vec3(-0.55, 0.45, -0.70).normalized(), Vec3(-0.55, -0.45, -0.70).normalized()};
  Vec3 tail = Vec3(-0.93, 0, 0.37).normalized();
  /// Unit tangents at `head`: toward the top of the head and toward the animal's left.
  Vec3 head_up = Vec3(-0.60, 0, 0.80);
  Vec3 head_left = Vec3(0, 1, 0);
  /// `head` rotated by the given angles (radians) toward head_up and head_left.
  Vec3 on_head(double up, double left) const {
    return (head + std::tan(up) * head_up + std::tan(left) * head_left).normalized();
  }
  Vec3 ear(int side) const { return on_head(0.16, 0.14 * side); }  // side +1 left, -1 right
  /// The snout sits on the lower half of the head's end, its apex is the nose tip.
  Vec3 snout() const { return on_head(-0.07, 0); }
};

struct TemplateLandmark {
  std::string name;
  Vec3 u;
};

/// The landmarks: apexes of the limbs, plus points of the body and head. Same names and
/// order in every member.
inline std::vector<TemplateLandmark> template_landmarks() {
  const AnimalTemplate t;
  return {{"nose_tip", t.snout()},
          {"left_ear_tip", t.ear(+1)},
          {"right_ear_tip", t.ear(-1)},
          {"chin", t.on_head(-0.34, 0)},
          {"front_left_paw", t.legs[0]},
          {"front_right_paw", t.legs[1]},
          {"hind_left_paw", t.legs[2]},
          {"hind_right_paw", t.legs[3]},
          {"tail_tip", t.tail},
          {"back", Vec3(-0.15, 0, 1).normalized()},
          {"belly", Vec3(0.20, 0, -1).normalized()},
          {"rump", Vec3(-0.60, 0, 0.80).normalized()},
          {"chest", Vec3(0.95, 0, -0.30).normalized()}};
}

/// A spherical cap of the template: the faces whose template centroid lies inside are
/// removed to make a hole. Both caps keep clear of every landmark by more than 1.8 times
/// their radius (the mouth lies 0.13 rad below the nose tip and 0.14 above the chin).
struct Cap {
  Vec3 centre;
  double radius;  ///< radians
};
inline Cap mouth_cap() { return {AnimalTemplate().on_head(-0.2, 0), 0.07}; }
inline Cap belly_cap() { return {Vec3(-0.20, 0, -1).normalized(), 0.14}; }

struct Bump {
  Vec3 base;        ///< B(c_i): the footprint centre on the body
  double inv_r2;    ///< 1 / r_i^2
  double length;    ///< L_i
  Vec3 direction;   ///< t_i, unit
};

struct AnimalShape {
  Vec3 scale;
  std::vector<Bump> bumps;

  Vec3 operator()(const Vec3& u) const {
    const Vec3 body = scale.cwiseProduct(u);
    Vec3 x = body;
    for (const Bump& b : bumps) {
      const double q = (body - b.base).squaredNorm() * b.inv_r2;
      const double e = q * std::sqrt(q);
      // exp(-40) ~ 4e-18: beyond that the bump adds nothing representable to the body.
      if (e < 40) x += b.length * std::exp(-e) * b.direction;
    }
    return x;
  }
};

/// Unit vector from an elevation (above the horizontal plane) and an azimuth (from +x
/// toward +y), both in radians.
inline Vec3 direction(double elevation, double azimuth) {
  return Vec3(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
}

/// Proportions and pose of one member, drawn from ranges chosen so every member stays an
/// embedded, recognisable quadruped (see the file comment).
inline AnimalShape random_animal(Rng& rng) {
  const AnimalTemplate t;
  AnimalShape s;
  s.scale = Vec3(rng.uniform(1.5, 2.0), rng.uniform(0.72, 0.85), rng.uniform(0.75, 0.9));
  auto add = [&](const Vec3& centre, double radius, double length, const Vec3& dir) {
    s.bumps.push_back({s.scale.cwiseProduct(centre), 1 / (radius * radius), length, dir.normalized()});
  };
  // Legs: one length and thickness per animal; each leg swings forward/back by up to 20
  // degrees and splays outward by up to 17 degrees, which keeps t . normal > 0.5.
  const double leg_length = rng.uniform(0.7, 1.2), leg_radius = rng.uniform(0.2, 0.25);
  for (int i = 0; i < 4; ++i) {
    const double swing = rng.uniform(-0.35, 0.35), splay = rng.uniform(0.0, 0.3);
    const double side = t.legs[i].y() > 0 ? 1 : -1;
    add(t.legs[i], leg_radius, leg_length,
        Vec3(std::sin(swing), side * std::sin(splay), -std::cos(swing) * std::cos(splay)));
  }
  // Tail: from hanging slightly to raised high, swishing sideways.
  add(t.tail, rng.uniform(0.11, 0.15), rng.uniform(0.8, 1.4),
      -direction(-rng.uniform(-0.2, 0.9), rng.uniform(-0.4, 0.4)));
  // Neck and head, a snout on the lower half of its end, ears on its top rim.
  const double head_radius = rng.uniform(0.36, 0.44);
  const Vec3 head_dir = direction(rng.uniform(0.1, 0.8), rng.uniform(-0.35, 0.35));
  add(t.head, head_radius, rng.uniform(0.55, 0.95), head_dir);
  add(t.snout(), 0.5 * head_radius, rng.uniform(0.18, 0.32), head_dir);
  const double ear_length = rng.uniform(0.2, 0.35), ear_radius = rng.uniform(0.08, 0.1);
  const double ear_tilt = rng.uniform(-0.2, 0.5), ear_spread = rng.uniform(0.1, 0.6);
  for (int side : {+1, -1})
    add(t.ear(side), ear_radius, ear_length,
        Vec3(-std::sin(ear_tilt), side * ear_spread, std::cos(ear_tilt)));
  return s;
}

}  // namespace spherekit::samples::detail

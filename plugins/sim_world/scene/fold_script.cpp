#include "plugins/sim_world/scene/fold_script.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <numbers>

namespace crease::sheet {
namespace {

// Side of p relative to the line a-b (sheet coordinates): sign of the 2D cross product.
double side(Vec2 a, Vec2 b, Vec2 p) {
  return (b.u - a.u) * (p.v - a.v) - (b.v - a.v) * (p.u - a.u);
}

// Rodrigues rotation of p about the axis through o with unit direction k.
Vec3 rotate(Vec3 p, Vec3 o, Vec3 k, double angle) {
  const Vec3 r = p - o;
  const double c = std::cos(angle), s = std::sin(angle);
  return o + c * r + s * cross(k, r) + ((1 - c) * dot(k, r)) * k;
}

}  // namespace

double Fold::theta_deg(double t) const noexcept {
  if (key_count == 0) return 0;
  if (t <= keys[0].t_s) return keys[0].theta_deg;
  for (int k = 1; k < key_count; ++k) {
    if (t <= keys[k].t_s) {
      const double f = (t - keys[k - 1].t_s) / (keys[k].t_s - keys[k - 1].t_s);
      return keys[k - 1].theta_deg + f * (keys[k].theta_deg - keys[k - 1].theta_deg);
    }
  }
  return keys[key_count - 1].theta_deg;
}

double FoldScript::duration_s() const noexcept {
  double d = 0;
  for (const Fold& f : folds_)
    if (f.key_count > 0) d = std::max(d, f.keys[f.key_count - 1].t_s);
  return d;
}

Vec3 FoldScript::position_after(Vec2 q, std::size_t n, double t) const noexcept {
  const Vec3& o = grid_.origin_mm;
  Vec3 x{o.x + q.u, o.y - q.v, o.z};
  for (std::size_t k = 0; k < n; ++k) {
    const Fold& f = folds_[k];
    const double theta = f.theta_deg(t) * std::numbers::pi / 180.0;
    if (theta == 0) continue;
    if (side(f.a, f.b, q) * side(f.a, f.b, f.moving) <= 0) continue;
    // The axis is the crease where the earlier folds put it (recursion depth = fold count,
    // folds are few); turning direction: the moving side starts upwards (+z).
    const Vec3 a = position_after(f.a, k, t), b = position_after(f.b, k, t);
    const Vec3 m = position_after(f.moving, k, t);
    Vec3 axis = normalized(b - a);
    Vec3 out = m - a;
    out -= dot(out, axis) * axis;
    Vec3 up = cross(axis, out);
    if (up.z < 0) {
      axis = -1.0 * axis;
      up = -1.0 * up;
    }
    up = normalized(up);
    x = rotate(x, a + f.lift_mm * up, axis, theta);
  }
  return x;
}

Vec3 FoldScript::position(Vec2 p, double t) const noexcept {
  return position_after(p, folds_.size(), t);
}

void FoldScript::node_positions(double t, std::span<Vec3> out) const noexcept {
  const int w = grid_.nodes_u, h = grid_.nodes_v;
  const double du = grid_.width_mm / (w - 1), dv = grid_.height_mm / (h - 1);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const std::size_t idx = static_cast<std::size_t>(j * w + i);
      if (idx < out.size()) out[idx] = position({i * du, j * dv}, t);
    }
}

namespace {
Fold make_fold(Vec2 a, Vec2 b, Vec2 moving, double lift, std::initializer_list<FoldKey> keys) {
  Fold f;
  f.a = a;
  f.b = b;
  f.moving = moving;
  f.lift_mm = lift;
  for (const FoldKey& k : keys) f.keys[f.key_count++] = k;
  return f;
}
}  // namespace

FoldScript FoldScript::half_fold(const GridParams& g) {
  FoldScript s(g);
  const double mid = g.height_mm / 2, t = g.thickness_mm;
  s.add(make_fold({0, mid}, {g.width_mm, mid}, {g.width_mm / 2, 0}, 0.5 * t,
                  {{0, 0}, {5, 175}, {8, 175}}));
  return s;
}

FoldScript FoldScript::diagonal_fold(const GridParams& g) {
  FoldScript s(g);
  const double w = g.width_mm, t = g.thickness_mm;
  s.add(make_fold({w / 2, 0}, {w, w / 2}, {w, 0}, 0.5 * t, {{0, 0}, {4, 170}, {6, 170}}));
  return s;
}

FoldScript FoldScript::two_folds(const GridParams& g) {
  FoldScript s(g);
  const double mid = g.height_mm / 2, t = g.thickness_mm, w = g.width_mm;
  s.add(make_fold({0, mid}, {w, mid}, {w / 2, 0}, 0.5 * t, {{0, 0}, {5, 180}, {12, 180}}));
  s.add(make_fold({w / 2, g.height_mm}, {w / 2, mid + 1}, {w, g.height_mm}, 1.5 * t,
                  {{6, 0}, {11, 180}, {12, 180}}));
  return s;
}

FoldScript FoldScript::unfold(const GridParams& g) {
  FoldScript s(g);
  const double mid = g.height_mm / 2, t = g.thickness_mm;
  s.add(make_fold({0, mid}, {g.width_mm, mid}, {g.width_mm / 2, 0}, 0.5 * t,
                  {{0, 0}, {5, 175}, {6, 175}, {11, 0}, {12, 0}}));
  return s;
}

}  // namespace crease::sheet

#include "plugins/fold_sequence/sheet_geometry.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace crease::fold {
namespace {

bool node(const SheetState& s, int i, int j, double out[3]) noexcept {
  const float* p = s.position_mm[static_cast<std::size_t>(j) * s.nodes_u + static_cast<std::size_t>(i)];
  for (int c = 0; c < 3; ++c) {
    out[c] = p[c];
    if (!std::isfinite(out[c])) return false;
  }
  return true;
}

bool usable(const SheetState& s) noexcept {
  return s.nodes_u >= 2 && s.nodes_v >= 2 &&
         static_cast<std::uint32_t>(s.nodes_u) * s.nodes_v <= SheetState::kMaxNodes && s.width_mm > 0 &&
         s.height_mm > 0;
}

double norm(const double v[3]) noexcept { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

}  // namespace

void sheet_to_world(const SheetFrame& f, const double p[3], double out[3]) noexcept {
  for (int c = 0; c < 3; ++c) out[c] = f.origin[c] + f.x[c] * p[0] + f.y[c] * p[1] + f.z[c] * p[2];
}

namespace {
Eigen::Matrix3d rotation(const SheetFrame& f) noexcept {  // the frame's axes as columns
  Eigen::Matrix3d r;
  r << f.x[0], f.y[0], f.z[0], f.x[1], f.y[1], f.z[1], f.x[2], f.y[2], f.z[2];
  return r;
}
}  // namespace

void sheet_to_world(const SheetFrame& f, const double p[3], const double q[4], double p_out[3],
                    double q_out[4]) noexcept {
  sheet_to_world(f, p, p_out);
  const Eigen::Quaterniond turn =
      Eigen::Quaterniond(rotation(f)) * Eigen::Quaterniond(q[3], q[0], q[1], q[2]);
  q_out[0] = turn.x(), q_out[1] = turn.y(), q_out[2] = turn.z(), q_out[3] = turn.w();
}

void world_to_sheet(const SheetFrame& f, const double p[3], const double q[4], double p_out[3],
                    double q_out[4]) noexcept {
  const Eigen::Matrix3d r = rotation(f);
  const Eigen::Vector3d d = r.transpose() * (Eigen::Vector3d(p[0], p[1], p[2]) -
                                             Eigen::Map<const Eigen::Vector3d>(f.origin));
  const Eigen::Quaterniond turn =
      Eigen::Quaterniond(r).conjugate() * Eigen::Quaterniond(q[3], q[0], q[1], q[2]);
  for (int c = 0; c < 3; ++c) p_out[c] = d[c];
  q_out[0] = turn.x(), q_out[1] = turn.y(), q_out[2] = turn.z(), q_out[3] = turn.w();
}

bool sheet_frame(const SheetState& s, SheetFrame& f) noexcept {
  if (!usable(s)) return false;
  double o[3], a[3], b[3];
  // Node (0, quarter) for v, as arm_motion's frame (plugins/arm_motion/sheet_frame.h): the far
  // corner is what a fold lifts, the half fold's crease what it loops.
  const int quarter = std::max(1, (s.nodes_v - 1) / 4);
  if (!node(s, 0, 0, o) || !node(s, s.nodes_u - 1, 0, a) || !node(s, 0, quarter, b)) return false;
  double u[3] = {a[0] - o[0], a[1] - o[1], a[2] - o[2]};
  const double v[3] = {b[0] - o[0], b[1] - o[1], b[2] - o[2]};
  const double nu = norm(u);
  if (nu < 1e-6) return false;
  for (double& c : u) c /= nu;
  double z[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  const double nz = norm(z);
  if (nz < 1e-6) return false;
  for (double& c : z) c /= nz;
  for (int c = 0; c < 3; ++c) {
    f.origin[c] = o[c];
    f.x[c] = u[c];
    f.z[c] = z[c];
  }
  f.y[0] = z[1] * u[2] - z[2] * u[1];
  f.y[1] = z[2] * u[0] - z[0] * u[2];
  f.y[2] = z[0] * u[1] - z[1] * u[0];
  return true;
}

double frame_yaw(const SheetFrame& f) noexcept {
  return std::atan2(f.x[1], f.x[0]);
}

void turn_about_vertical(const SheetFrame& f, double alpha_rad, const double q[4],
                         double q_out[4]) noexcept {
  const Eigen::Quaterniond r(rotation(f));
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(alpha_rad, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond out =
      r.conjugate() * turn * r * Eigen::Quaterniond(q[3], q[0], q[1], q[2]);
  q_out[0] = out.x(), q_out[1] = out.y(), q_out[2] = out.z(), q_out[3] = out.w();
}

bool node_at(const SheetState& s, double u, double v, double out[3]) noexcept {
  if (!usable(s) || !std::isfinite(u) || !std::isfinite(v)) return false;
  const int i = std::clamp(static_cast<int>(std::lround(u / s.width_mm * (s.nodes_u - 1))), 0, s.nodes_u - 1);
  const int j = std::clamp(static_cast<int>(std::lround(v / s.height_mm * (s.nodes_v - 1))), 0, s.nodes_v - 1);
  return node(s, i, j, out);
}

bool nearest_crease(const SheetState& s, double a[2], double b[2]) noexcept {
  const std::uint32_t n = std::min(s.crease_count, SheetState::kMaxCreases);
  double best = 1e300;
  double ba[2] = {0, 0}, bb[2] = {0, 0};
  for (std::uint32_t k = 0; k < n; ++k) {
    const float* c = s.crease_mm[k];
    const double same = std::hypot(c[0] - a[0], c[1] - a[1]) + std::hypot(c[2] - b[0], c[3] - b[1]);
    const double flip = std::hypot(c[2] - a[0], c[3] - a[1]) + std::hypot(c[0] - b[0], c[1] - b[1]);
    if (!std::isfinite(same) || !std::isfinite(flip)) continue;
    if (same < best) {
      best = same;
      ba[0] = c[0], ba[1] = c[1], bb[0] = c[2], bb[1] = c[3];
    }
    if (flip < best) {
      best = flip;
      ba[0] = c[2], ba[1] = c[3], bb[0] = c[0], bb[1] = c[1];
    }
  }
  if (best == 1e300) return false;
  a[0] = ba[0], a[1] = ba[1], b[0] = bb[0], b[1] = bb[1];
  return true;
}

}  // namespace crease::fold

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

double beyond_line(const double a[2], const double b[2], const double side[2], double u,
                   double v) noexcept {
  const double lx = b[0] - a[0], ly = b[1] - a[1], len = std::hypot(lx, ly);
  if (!(len > 0)) return std::nan("");
  const double sign = (lx * (side[1] - a[1]) - ly * (side[0] - a[0])) >= 0 ? 1.0 : -1.0;
  return sign * (lx * (v - a[1]) - ly * (u - a[0])) / len;
}

bool part_point_under(const SheetState& s, const double a[2], const double b[2],
                      const double side[2], const double p[3], double max_mm,
                      double uv[2]) noexcept {
  if (!usable(s) || !std::isfinite(beyond_line(a, b, side, 0, 0))) return false;
  const auto beyond = [&](double u, double v) { return beyond_line(a, b, side, u, v); };
  const double du = s.width_mm / (s.nodes_u - 1), dv = s.height_mm / (s.nodes_v - 1);
  int bi = -1, bj = -1;
  double best = max_mm * max_mm, q[3] = {0, 0, 0};
  for (int j = 0; j < s.nodes_v; ++j)
    for (int i = 0; i < s.nodes_u; ++i) {
      if (beyond(i * du, j * dv) < 1.0) continue;
      double n[3];
      if (!node(s, i, j, n)) continue;
      const double d2 = (n[0] - p[0]) * (n[0] - p[0]) + (n[1] - p[1]) * (n[1] - p[1]);
      if (d2 <= best) {
        best = d2;
        bi = i, bj = j;
        for (int c = 0; c < 3; ++c) q[c] = n[c];
      }
    }
  if (bi < 0) return false;
  uv[0] = bi * du;
  uv[1] = bj * dv;
  // One linear step: the grid's world x, y per mm of u and of v at the node (central
  // differences, one-sided at the border), solved for the offset to P, at most one cell.
  double e[2][2];
  for (int k = 0; k < 2; ++k) {
    const int n = k == 0 ? s.nodes_u : s.nodes_v, at = k == 0 ? bi : bj;
    const int lo = std::max(at - 1, 0), hi = std::min(at + 1, n - 1);
    double ql[3], qh[3];
    if (!node(s, k == 0 ? lo : bi, k == 0 ? bj : lo, ql) ||
        !node(s, k == 0 ? hi : bi, k == 0 ? bj : hi, qh))
      return true;
    const double span = (hi - lo) * (k == 0 ? du : dv);
    e[k][0] = (qh[0] - ql[0]) / span;
    e[k][1] = (qh[1] - ql[1]) / span;
  }
  const double det = e[0][0] * e[1][1] - e[1][0] * e[0][1];
  if (!(std::fabs(det) > 0.25)) return true;  // the part stands steep here: the node as it is
  const double rx = p[0] - q[0], ry = p[1] - q[1];
  const double su = (rx * e[1][1] - ry * e[1][0]) / det, sv = (e[0][0] * ry - e[0][1] * rx) / det;
  uv[0] = std::clamp(uv[0] + std::clamp(su, -du, du), 0.0, static_cast<double>(s.width_mm));
  uv[1] = std::clamp(uv[1] + std::clamp(sv, -dv, dv), 0.0, static_cast<double>(s.height_mm));
  return true;
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

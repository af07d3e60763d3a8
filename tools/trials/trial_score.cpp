#include "tools/trials/trial_score.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace crease::trials {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

struct Line {
  double a[2], dir[2], n[2];  // a point, the unit direction, the unit normal towards the flap
};

Line line_of(const FoldTarget& t) {
  Line l;
  const double dx = t.line_mm[1][0] - t.line_mm[0][0], dy = t.line_mm[1][1] - t.line_mm[0][1];
  const double len = std::hypot(dx, dy);
  l.a[0] = t.line_mm[0][0];
  l.a[1] = t.line_mm[0][1];
  l.dir[0] = len > 0 ? dx / len : 1.0;
  l.dir[1] = len > 0 ? dy / len : 0.0;
  l.n[0] = -l.dir[1];
  l.n[1] = l.dir[0];
  const double side = (t.flap_corner_mm[0] - l.a[0]) * l.n[0] + (t.flap_corner_mm[1] - l.a[1]) * l.n[1];
  if (side < 0) {
    l.n[0] = -l.n[0];
    l.n[1] = -l.n[1];
  }
  return l;
}

// Signed distance from the line, positive on the flap's side.
double side_of(const Line& l, const std::array<double, 2>& p) {
  return (p[0] - l.a[0]) * l.n[0] + (p[1] - l.a[1]) * l.n[1];
}

std::array<double, 2> mirror(const Line& l, const std::array<double, 2>& p) {
  const double d = side_of(l, p);
  return {p[0] - 2 * d * l.n[0], p[1] - 2 * d * l.n[1]};
}

int nodes(const SheetState& s) { return static_cast<int>(s.nodes_u) * s.nodes_v; }

// Least squares rigid motion from (u, m v) to (x, y) over the base's nodes; its mean residual.
double fit_with(const SheetState& s, const Line& l, double m, PlaneMotion& out, int& count) {
  double pc[2] = {0, 0}, xc[2] = {0, 0};
  count = 0;
  for (int j = 0; j < s.nodes_v; ++j)
    for (int i = 0; i < s.nodes_u; ++i) {
      const auto p = node_uv(s, i, j);
      if (side_of(l, p) > -kMarginMm) continue;
      const float* x = s.position_mm[j * s.nodes_u + i];
      pc[0] += p[0];
      pc[1] += m * p[1];
      xc[0] += x[0];
      xc[1] += x[1];
      ++count;
    }
  if (count < 3) return kNaN;
  for (double& v : pc) v /= count;
  for (double& v : xc) v /= count;
  double dot = 0, cross = 0;
  for (int j = 0; j < s.nodes_v; ++j)
    for (int i = 0; i < s.nodes_u; ++i) {
      const auto p = node_uv(s, i, j);
      if (side_of(l, p) > -kMarginMm) continue;
      const float* x = s.position_mm[j * s.nodes_u + i];
      const double pu = p[0] - pc[0], pv = m * p[1] - pc[1], xu = x[0] - xc[0], xv = x[1] - xc[1];
      dot += pu * xu + pv * xv;
      cross += pu * xv - pv * xu;
    }
  const double th = std::atan2(cross, dot);
  PlaneMotion t;
  t.c = std::cos(th);
  t.s = std::sin(th);
  t.tx = xc[0] - (t.c * pc[0] - t.s * pc[1]);
  t.ty = xc[1] - (t.s * pc[0] + t.c * pc[1]);
  double res = 0;
  for (int j = 0; j < s.nodes_v; ++j)
    for (int i = 0; i < s.nodes_u; ++i) {
      const auto p = node_uv(s, i, j);
      if (side_of(l, p) > -kMarginMm) continue;
      const float* x = s.position_mm[j * s.nodes_u + i];
      const auto y = t.apply(p[0], m * p[1]);
      res += std::hypot(y[0] - x[0], y[1] - x[1]);
    }
  out = t;
  return res / count;
}

// The fitted motion, taking (u, v) as they are (the flip folded into it).
struct BaseFit {
  PlaneMotion t;
  double m = 1;  // v's sign: the world's sheet has u along x, v along -y
  [[nodiscard]] std::array<double, 2> to_world(const std::array<double, 2>& p) const { return t.apply(p[0], m * p[1]); }
  [[nodiscard]] std::array<double, 2> to_sheet(double x, double y) const {
    const auto q = t.invert(x, y);
    return {q[0], m * q[1]};
  }
};

bool fit(const SheetState& s, const Line& l, BaseFit& out, int& count) {
  PlaneMotion a, b;
  int na = 0, nb = 0;
  const double ra = fit_with(s, l, 1.0, a, na), rb = fit_with(s, l, -1.0, b, nb);
  count = na;
  if (!std::isfinite(ra) && !std::isfinite(rb)) return false;
  if (!std::isfinite(rb) || (std::isfinite(ra) && ra <= rb)) {
    out.t = a;
    out.m = 1.0;
  } else {
    out.t = b;
    out.m = -1.0;
  }
  return true;
}

}  // namespace

std::array<double, 2> node_uv(const SheetState& s, int i, int j) noexcept {
  const double du = s.nodes_u > 1 ? s.width_mm / (s.nodes_u - 1) : 0.0;
  const double dv = s.nodes_v > 1 ? s.height_mm / (s.nodes_v - 1) : 0.0;
  return {i * du, j * dv};
}

bool fit_base(const SheetState& s, const FoldTarget& t, PlaneMotion& out, int* count) {
  BaseFit f;
  int n = 0;
  const bool ok = fit(s, line_of(t), f, n);
  if (count != nullptr) *count = n;
  out = f.t;
  return ok;
}

double max_stretch(const SheetState& s, double* at_uv_mm) {
  const int W = s.nodes_u, H = s.nodes_v;
  if (nodes(s) < 4 || nodes(s) > static_cast<int>(SheetState::kMaxNodes)) return kNaN;
  const double du = W > 1 ? s.width_mm / (W - 1) : 1.0, dv = H > 1 ? s.height_mm / (H - 1) : 1.0;
  double worst = 0;
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      const float* x = s.position_mm[j * W + i];
      auto stretch = [&](const float* y, double rest, double di, double dj) {
        const double d = std::sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) + (x[2] - y[2]) * (x[2] - y[2]));
        const double e = (d - rest) / rest;
        if (e <= worst) return;
        worst = e;
        if (at_uv_mm == nullptr) return;
        at_uv_mm[0] = du * (i + di);
        at_uv_mm[1] = dv * (j + dj);
      };
      if (i + 1 < W) stretch(s.position_mm[j * W + i + 1], du, 0.5, 0.0);
      if (j + 1 < H) stretch(s.position_mm[(j + 1) * W + i], dv, 0.0, 0.5);
    }
  return worst;
}

Score score_sheet(const SheetState& s, const FoldTarget& target, const Bounds& b, const SheetState* reference) {
  Score r;
  r.fold_line_mm = r.fold_angle_deg = r.corners_mm = r.retained_deg = r.slip_mm = kNaN;
  const Line l = line_of(target);
  BaseFit base;
  if (nodes(s) < 4 || nodes(s) > static_cast<int>(SheetState::kMaxNodes) || !fit(s, l, base, r.base_nodes)) {
    r.miss = "no sheet to score";
    return r;
  }
  r.valid = true;
  const int W = s.nodes_u, H = s.nodes_v;
  auto pos = [&](int i, int j) { return s.position_mm[j * W + i]; };

  // The flap: where its nodes lie seen through the base's motion; the fold line they show.
  double nsum[2] = {0, 0}, msum[2] = {0, 0};
  std::vector<std::array<double, 2>> mids;
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      const auto p = node_uv(s, i, j);
      if (side_of(l, p) < kMarginMm) continue;
      ++r.flap_nodes;
      const float* x = pos(i, j);
      const auto q = base.to_sheet(x[0], x[1]);
      const double d[2] = {p[0] - q[0], p[1] - q[1]};
      const double len = std::hypot(d[0], d[1]);
      if (x[2] > kOnBaseMm || x[2] < -kBelowTableMm || len < kFoldedMm) continue;  // on the base, not hanging
      ++r.folded_nodes;
      nsum[0] += d[0] / len;
      nsum[1] += d[1] / len;
      mids.push_back({0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])});
      msum[0] += mids.back()[0];
      msum[1] += mids.back()[1];
    }
  if (r.flap_nodes > 0 && 2 * r.folded_nodes >= r.flap_nodes) {
    const double nl = std::hypot(nsum[0], nsum[1]);
    const double n1[2] = {nsum[0] / nl, nsum[1] / nl};
    double c1 = 0;
    for (const auto& m : mids) c1 += n1[0] * m[0] + n1[1] * m[1];
    c1 /= static_cast<double>(mids.size());
    const double mid0[2] = {0.5 * (target.line_mm[0][0] + target.line_mm[1][0]),
                            0.5 * (target.line_mm[0][1] + target.line_mm[1][1])};
    r.fold_line_mm = std::fabs(n1[0] * mid0[0] + n1[1] * mid0[1] - c1);
    r.fold_angle_deg = std::acos(std::min(1.0, std::fabs(n1[0] * l.n[0] + n1[1] * l.n[1]))) * 180.0 / kPi;
  }

  // The flap's corners against where the intended fold puts them (on the base's plane, z 0).
  r.corners_mm = 0;
  const int corner_ij[4][2] = {{0, 0}, {W - 1, 0}, {0, H - 1}, {W - 1, H - 1}};
  for (const auto& c : corner_ij) {
    const auto p = node_uv(s, c[0], c[1]);
    if (side_of(l, p) <= 1.0) continue;
    const auto want = base.to_world(mirror(l, p));
    const float* x = pos(c[0], c[1]);
    r.corners_mm = std::max(r.corners_mm, std::sqrt((x[0] - want[0]) * (x[0] - want[0]) +
                                                    (x[1] - want[1]) * (x[1] - want[1]) + double(x[2]) * x[2]));
  }

  // The angle the crease keeps: the mean normals either side of the line.
  double na[3] = {0, 0, 0}, nb[3] = {0, 0, 0};
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      const double d = side_of(l, node_uv(s, i, j));
      const double ad = std::fabs(d);
      if (ad < kRetainedNearMm || ad > kRetainedFarMm) continue;
      double* acc = d > 0 ? na : nb;
      for (int k = 0; k < 3; ++k) acc[k] += s.normal[j * W + i][k];
    }
  const double la = std::sqrt(na[0] * na[0] + na[1] * na[1] + na[2] * na[2]);
  const double lb = std::sqrt(nb[0] * nb[0] + nb[1] * nb[1] + nb[2] * nb[2]);
  if (la > 0 && lb > 0) {
    const double c = (na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2]) / (la * lb);
    r.retained_deg = std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi;
  }

  // Damage: the grid's edges against their rest lengths; below the table.
  double zmin = 1e9;
  int below = 0;
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      const float* x = pos(i, j);
      zmin = std::min(zmin, double(x[2]));
      below += x[2] < -kBelowTableMm;
    }
  r.max_stretch = max_stretch(s, r.stretch_at_mm);
  r.torn = r.max_stretch > kTornStretch;
  r.off_table = below >= kOffTableFraction * W * H;

  // The base's slip from the reference.
  BaseFit ref;
  int n_ref = 0;
  if (reference != nullptr && reference->nodes_u == s.nodes_u && reference->nodes_v == s.nodes_v &&
      fit(*reference, l, ref, n_ref)) {
    r.slip_mm = 0;
    for (int j = 0; j < H; ++j)
      for (int i = 0; i < W; ++i) {
        const auto p = node_uv(s, i, j);
        if (side_of(l, p) > -kMarginMm) continue;
        const auto a = base.to_world(p), c = ref.to_world(p);
        r.slip_mm = std::max(r.slip_mm, std::hypot(a[0] - c[0], a[1] - c[1]));
      }
  }

  char buf[96];
  if (r.torn) {
    std::snprintf(buf, sizeof buf, "torn (an edge stretched %.1f %% at u %.0f v %.0f mm)",
                  100 * r.max_stretch, r.stretch_at_mm[0], r.stretch_at_mm[1]);
  } else if (r.off_table) {
    std::snprintf(buf, sizeof buf, "off the table (%d of %d nodes below its top, down to %.1f mm)", below, W * H, -zmin);
  } else if (!std::isfinite(r.fold_line_mm)) {
    std::snprintf(buf, sizeof buf, "no fold (%d of %d flap nodes folded onto the base)", r.folded_nodes, r.flap_nodes);
  } else if (r.fold_line_mm > b.fold_line_mm) {
    std::snprintf(buf, sizeof buf, "fold line %.1f mm > %.1f", r.fold_line_mm, b.fold_line_mm);
  } else if (r.fold_angle_deg > b.fold_angle_deg) {
    std::snprintf(buf, sizeof buf, "fold line at %.1f deg > %.1f", r.fold_angle_deg, b.fold_angle_deg);
  } else if (!(r.corners_mm <= b.corners_mm)) {
    std::snprintf(buf, sizeof buf, "corners %.1f mm > %.1f", r.corners_mm, b.corners_mm);
  } else if (!(r.retained_deg >= b.retained_deg)) {
    std::snprintf(buf, sizeof buf, "retained %.1f deg < %.1f", r.retained_deg, b.retained_deg);
  } else {
    buf[0] = '\0';
  }
  r.miss = buf;
  r.shape_ok = r.miss.empty();
  return r;
}

}  // namespace crease::trials

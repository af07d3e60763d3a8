#include "plugins/sim_world/scene/shape_view.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace crease::vision {

namespace {

using world::Geom;
using world::GeomKind;
using world::Pose;

constexpr double kInfD = std::numeric_limits<double>::infinity();
constexpr float kInfF = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

struct LatticePoint {
  float s;  // camera z where the ray enters the shape; +inf: it misses; NaN: not cast
  float lambert;
};

// A ray's interval [in, out] inside a solid piece, and the outward normal where it enters.
struct Span {
  double in = kInfD, out = -kInfD;
  cv::Vec3d normal;
  [[nodiscard]] bool empty() const { return !(in <= out); }
};

// Solid sphere of radius r centred at (0, 0, zc) (local frame).
Span sphere_span(const cv::Vec3d& o, const cv::Vec3d& d, double zc, double r) {
  const cv::Vec3d oc(o[0], o[1], o[2] - zc);
  const double a = d.dot(d), b = 2 * d.dot(oc), c = oc.dot(oc) - r * r;
  const double disc = b * b - 4 * a * c;
  Span sp;
  if (disc < 0 || a <= 0) return sp;
  const double q = std::sqrt(disc);
  sp.in = (-b - q) / (2 * a);
  sp.out = (-b + q) / (2 * a);
  sp.normal = (oc + sp.in * d) * (1.0 / r);
  return sp;
}

// Solid cylinder of radius r along z, |z| <= h (local frame).
Span cylinder_span(const cv::Vec3d& o, const cv::Vec3d& d, double r, double h) {
  Span sp;
  // The infinite cylinder.
  double c_in = -kInfD, c_out = kInfD;
  const double a = d[0] * d[0] + d[1] * d[1];
  const double c = o[0] * o[0] + o[1] * o[1] - r * r;
  if (a < 1e-18) {
    if (c > 0) return sp;  // parallel to the axis, outside
  } else {
    const double b = 2 * (o[0] * d[0] + o[1] * d[1]);
    const double disc = b * b - 4 * a * c;
    if (disc < 0) return sp;
    const double q = std::sqrt(disc);
    c_in = (-b - q) / (2 * a);
    c_out = (-b + q) / (2 * a);
  }
  // The slab |z| <= h.
  double z_in = -kInfD, z_out = kInfD;
  if (std::abs(d[2]) < 1e-18) {
    if (std::abs(o[2]) > h) return sp;
  } else {
    const double t0 = (-h - o[2]) / d[2], t1 = (h - o[2]) / d[2];
    z_in = std::min(t0, t1);
    z_out = std::max(t0, t1);
  }
  sp.in = std::max(c_in, z_in);
  sp.out = std::min(c_out, z_out);
  if (c_in >= z_in) {
    const cv::Vec3d p = o + c_in * d;
    sp.normal = cv::Vec3d(p[0], p[1], 0) * (1.0 / r);
  } else {
    sp.normal = cv::Vec3d(0, 0, d[2] > 0 ? -1.0 : 1.0);
  }
  return sp;
}

// The union of convex pieces: the earliest entry beyond s_min of any piece the ray meets.
void take(const Span& sp, double s_min, double& best, cv::Vec3d& normal) {
  if (sp.empty() || sp.out <= s_min || sp.in <= s_min)
    return;  // missed, behind, or the camera inside
  if (sp.in < best) {
    best = sp.in;
    normal = sp.normal;
  }
}

// The rounded box (shape_geometry.h: the core box, half extents h - r, grown by r = min h),
// exactly: the ray's entry into the whole box h is on a face unless it lies beyond the core on
// two axes; then it meets the rounded edges or the corner of that octant first (I. Quilez,
// "Rounded box - intersection", iquilezles.org, the same construction).
bool box_hit(const Geom& g, const cv::Vec3d& o_in, const cv::Vec3d& d_in, double s_min, double& s,
             cv::Vec3d& normal) {
  const double h[3] = {g.half_mm.x, g.half_mm.y, g.half_mm.z};
  const double r = std::min({h[0], h[1], h[2]});
  const double core[3] = {h[0] - r, h[1] - r, h[2] - r};
  double in = -kInfD, out = kInfD;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d_in[a]) < 1e-18) {
      if (std::abs(o_in[a]) > h[a]) return false;
      continue;
    }
    const double t0 = (-h[a] - o_in[a]) / d_in[a], t1 = (h[a] - o_in[a]) / d_in[a];
    in = std::max(in, std::min(t0, t1));
    out = std::min(out, std::max(t0, t1));
  }
  if (!(in <= out) || in <= s_min) return false;  // missed, behind, or the camera inside the box
  // Into the octant of the entry point.
  const cv::Vec3d entry = o_in + in * d_in;
  const cv::Vec3d sg(entry[0] < 0 ? -1 : 1, entry[1] < 0 ? -1 : 1, entry[2] < 0 ? -1 : 1);
  const cv::Vec3d o = o_in.mul(sg), d = d_in.mul(sg), p = entry.mul(sg);
  double t = kInfD;
  int beyond = 0;
  for (int a = 0; a < 3; ++a) beyond += p[a] > core[a];
  if (beyond <= 1) {
    t = in;  // on a flat face
  } else {
    const cv::Vec3d oc(o[0] - core[0], o[1] - core[1], o[2] - core[2]);
    const double r2 = r * r;
    {  // the corner's sphere
      const double a = d.dot(d), b = oc.dot(d), c = oc.dot(oc) - r2, disc = b * b - a * c;
      if (disc > 0) t = (-b - std::sqrt(disc)) / a;
    }
    for (int ax = 0; ax < 3; ++ax) {  // the edges along each axis
      const int u = (ax + 1) % 3, v = (ax + 2) % 3;
      const double a = d[u] * d[u] + d[v] * d[v];
      if (a < 1e-18) continue;
      const double b = oc[u] * d[u] + oc[v] * d[v], c = oc[u] * oc[u] + oc[v] * oc[v] - r2,
                   disc = b * b - a * c;
      if (disc <= 0) continue;
      const double te = (-b - std::sqrt(disc)) / a;
      if (te > 0 && te < t && std::abs(o[ax] + d[ax] * te) <= core[ax]) t = te;
    }
    if (t == kInfD || t <= s_min) return false;
  }
  s = t;
  const cv::Vec3d q0 = o_in + t * d_in;
  const cv::Vec3d q(q0[0] - std::clamp(q0[0], -core[0], core[0]),
                    q0[1] - std::clamp(q0[1], -core[1], core[1]),
                    q0[2] - std::clamp(q0[2], -core[2], core[2]));
  const double len = std::sqrt(q.dot(q));
  normal = len > 1e-12 ? q * (1.0 / len) : cv::Vec3d(0, 0, d_in[2] > 0 ? -1.0 : 1.0);
  return true;
}

cv::Vec3d local(const Pose& p, const cv::Vec3d& v) {  // R^T v
  return {p.r[0] * v[0] + p.r[3] * v[1] + p.r[6] * v[2],
          p.r[1] * v[0] + p.r[4] * v[1] + p.r[7] * v[2],
          p.r[2] * v[0] + p.r[5] * v[1] + p.r[8] * v[2]};
}

cv::Vec3d world_dir(const Pose& p, const cv::Vec3d& v) {  // R v
  return {p.r[0] * v[0] + p.r[1] * v[1] + p.r[2] * v[2],
          p.r[3] * v[0] + p.r[4] * v[1] + p.r[5] * v[2],
          p.r[6] * v[0] + p.r[7] * v[1] + p.r[8] * v[2]};
}

// Local-frame intersection: origin O, direction D (not unit: s is the caller's parameter).
bool intersect_local(const Geom& g, const cv::Vec3d& o, const cv::Vec3d& d, double s_min, double& s,
                     cv::Vec3d& n) {
  double best = kInfD;
  switch (g.kind) {
    case GeomKind::sphere:
      take(sphere_span(o, d, 0, g.radius_mm), s_min, best, n);
      break;
    case GeomKind::capsule:
      take(cylinder_span(o, d, g.radius_mm, g.half_length_mm), s_min, best, n);
      take(sphere_span(o, d, g.half_length_mm, g.radius_mm), s_min, best, n);
      take(sphere_span(o, d, -g.half_length_mm, g.radius_mm), s_min, best, n);
      break;
    case GeomKind::cylinder:
      take(cylinder_span(o, d, g.radius_mm, g.half_length_mm), s_min, best, n);
      break;
    case GeomKind::box:
      return box_hit(g, o, d, s_min, s, n);
  }
  if (best == kInfD) return false;
  s = best;
  return true;
}

// The pixels whose rays can meet the shape: its world bounding box, clipped to the space in front
// of the camera (z >= kNear), spans a rectangle of normalized (x, y) (the pinhole projection of a
// convex body in front of the camera is the hull of its vertices' projections); the pixel
// rectangle is every column and row whose rays reach into it. Empty when nothing is in front.
constexpr double kNear = 1.0;  // mm, camera z

struct InView {
  cv::Rect rect;      // pixels
  double z_near = 0;  // the nearest camera z the shape can have there, mm
  double z_far = 0;   // the farthest
  std::size_t index = 0;
};

InView pixel_rect(const Camera& cam, const RayBounds& rb, const SceneShape& sh) {
  const cv::Vec3d centre(sh.pose.t.x, sh.pose.t.y, sh.pose.t.z);
  const cv::Vec3d half(world::half_extent(sh.geom, sh.pose, 0),
                       world::half_extent(sh.geom, sh.pose, 1),
                       world::half_extent(sh.geom, sh.pose, 2));
  cv::Vec3d v[8];
  for (int k = 0; k < 8; ++k)
    v[k] =
        cam.to_camera(centre + cv::Vec3d((k & 1) ? half[0] : -half[0], (k & 2) ? half[1] : -half[1],
                                         (k & 4) ? half[2] : -half[2]));
  double x0 = kInfD, x1 = -kInfD, y0 = kInfD, y1 = -kInfD, z0 = kInfD, z1 = -kInfD;
  const auto add = [&](const cv::Vec3d& p) {
    z0 = std::min(z0, p[2]);
    z1 = std::max(z1, p[2]);
    x0 = std::min(x0, p[0] / p[2]);
    x1 = std::max(x1, p[0] / p[2]);
    y0 = std::min(y0, p[1] / p[2]);
    y1 = std::max(y1, p[1] / p[2]);
  };
  for (int k = 0; k < 8; ++k) {
    if (v[k][2] >= kNear) add(v[k]);
    for (int bit = 1; bit < 8; bit <<= 1) {  // the edges from k to its neighbours, once each
      if (k & bit) continue;
      const cv::Vec3d& a = v[k];
      const cv::Vec3d& b = v[k | bit];
      if ((a[2] >= kNear) != (b[2] >= kNear)) add(a + (b - a) * ((kNear - a[2]) / (b[2] - a[2])));
    }
  }
  if (!(x0 <= x1) || !(y0 <= y1)) return {};  // wholly behind the camera
  const int W = cam.width, H = cam.height;
  int c0 = 0, c1 = W - 1, r0 = 0, r1 = H - 1;
  while (c0 < W && rb.col_hi[c0] < x0) ++c0;
  while (c1 >= c0 && rb.col_lo[c1] > x1) --c1;
  while (r0 < H && rb.row_hi[r0] < y0) ++r0;
  while (r1 >= r0 && rb.row_lo[r1] > y1) --r1;
  if (c0 > c1 || r0 > r1) return {};
  return {{c0, r0, c1 - c0 + 1, r1 - r0 + 1}, z0, z1, 0};
}

// The shape's smallest thickness (mm): no section through it is thinner.
double thickness(const Geom& g) {
  return g.kind == GeomKind::box ? 2 * std::min({g.half_mm.x, g.half_mm.y, g.half_mm.z})
                                 : 2 * g.radius_mm;
}

}  // namespace

void shapes_of(const crease::WorldShapes& in, std::vector<SceneShape>& out) {
  const std::uint32_t n = std::min(in.count, crease::WorldShapes::kCapacity);
  out.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const crease::WorldShapes::Shape& s = in.shapes[i];
    SceneShape& o = out[i];
    o.geom.kind = static_cast<GeomKind>(s.kind);
    o.geom.radius_mm = s.radius_mm;
    o.geom.half_length_mm = s.half_length_mm;
    o.geom.half_mm = {s.half_mm[0], s.half_mm[1], s.half_mm[2]};
    o.pose.t = {s.position_mm[0], s.position_mm[1], s.position_mm[2]};
    for (int k = 0; k < 9; ++k) o.pose.r[k] = s.rotation[k];
    o.role = s.role;
    o.side = s.side;
  }
}

bool intersect_shape(const SceneShape& sh, const cv::Vec3d& c, const cv::Vec3d& d, double s_min,
                     double& s, cv::Vec3d& normal) {
  const cv::Vec3d o = local(sh.pose, c - cv::Vec3d(sh.pose.t.x, sh.pose.t.y, sh.pose.t.z));
  cv::Vec3d n;
  if (!intersect_local(sh.geom, o, local(sh.pose, d), s_min, s, n)) return false;
  normal = world_dir(sh.pose, n);
  return true;
}

RayBounds ray_bounds(const cv::Mat& rays) {
  RayBounds b;
  b.col_lo.assign(static_cast<std::size_t>(rays.cols), std::numeric_limits<float>::infinity());
  b.col_hi.assign(static_cast<std::size_t>(rays.cols), -std::numeric_limits<float>::infinity());
  b.row_lo.assign(static_cast<std::size_t>(rays.rows), std::numeric_limits<float>::infinity());
  b.row_hi.assign(static_cast<std::size_t>(rays.rows), -std::numeric_limits<float>::infinity());
  for (int y = 0; y < rays.rows; ++y) {
    const auto* r = rays.ptr<cv::Vec2f>(y);
    for (int x = 0; x < rays.cols; ++x) {
      const auto cx = static_cast<std::size_t>(x), cy = static_cast<std::size_t>(y);
      b.col_lo[cx] = std::min(b.col_lo[cx], r[x][0]);
      b.col_hi[cx] = std::max(b.col_hi[cx], r[x][0]);
      b.row_lo[cy] = std::min(b.row_lo[cy], r[x][1]);
      b.row_hi[cy] = std::max(b.row_hi[cy], r[x][1]);
    }
  }
  return b;
}

void draw_shapes(const Camera& cam, const cv::Mat& rays, const RayBounds& bounds,
                 std::span<const SceneShape> shapes, const ShapeDrawing& drawing,
                 const cv::Mat& sheet_depth, cv::Mat& image, cv::Mat& shape_depth, cv::Mat& mask) {
  const cv::Vec3d light = cv::normalize(cv::Vec3d(0.3, -0.2, 1.0));  // the renderer's
  const cv::Vec3d c = cam.centre_world();
  const cv::Matx33d rt = cam.R.t();
  // Nearest first: a pixel a nearer shape already covers is passed over by the farther ones.
  std::vector<LatticePoint> lattice;
  std::vector<InView> order;
  order.reserve(shapes.size());
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    InView v = pixel_rect(cam, bounds, shapes[i]);
    v.index = i;
    if (!v.rect.empty()) order.push_back(v);
  }
  std::sort(order.begin(), order.end(),
            [](const InView& a, const InView& b) { return a.z_near < b.z_near; });
  for (const InView& in_view : order) {
    const SceneShape& sh = shapes[in_view.index];
    const cv::Rect& box = in_view.rect;
    const auto z_near = static_cast<float>(in_view.z_near);
    // Local frame: origin o, direction m * (x, y, 1) (s stays the camera z).
    const cv::Vec3d o = local(sh.pose, c - cv::Vec3d(sh.pose.t.x, sh.pose.t.y, sh.pose.t.z));
    const cv::Vec3d m0 = local(sh.pose, rt * cv::Vec3d(1, 0, 0)),
                    m1 = local(sh.pose, rt * cv::Vec3d(0, 1, 0)),
                    m2 = local(sh.pose, rt * cv::Vec3d(0, 0, 1));
    // A ray that misses the shape's bounding sphere misses the shape: a cheap first test.
    const double rb = world::bounding_radius(sh.geom);
    const double oc = o.dot(o) - rb * rb;
    // Pixel (x, y)'s ray: where it enters the shape (camera z) and the lambertian term there.
    const auto cast = [&](int x, int y, float& s_out, float& lambert_out) {
      const cv::Vec2f ray = rays.at<cv::Vec2f>(y, x);
      const cv::Vec3d dl = m0 * ray[0] + m1 * ray[1] + m2;
      const double half_b = o.dot(dl);
      if (half_b * half_b < dl.dot(dl) * oc || (half_b > 0 && oc > 0))
        return false;  // misses it, or it lies behind
      double s = 0;
      cv::Vec3d n;
      if (!intersect_local(sh.geom, o, dl, kNear, s, n)) return false;
      s_out = static_cast<float>(s);
      lambert_out = static_cast<float>(std::max(0.0, world_dir(sh.pose, n).dot(light)));
      return true;
    };
    // Every kStep-th pixel of every kStep-th row first (a lattice); a pixel inside a lattice cell
    // whose four corners all meet the shape takes their bilinear interpolation (a shape is convex:
    // a ray between four that meet it meets it; and smooth: the interpolated depth is off by the
    // surface's sag over the cell, ShapeDrawing::lattice_px), every other pixel is cast.
    const int kStep = std::max(1, drawing.lattice_px);
    const int gw = (box.width - 1) / kStep + 1, gh = (box.height - 1) / kStep + 1;
    lattice.assign(static_cast<std::size_t>(gw) * static_cast<std::size_t>(gh), {kNaN, 0.f});
    for (int j = 0; j < gh; ++j) {
      const int y = box.y + kStep * j;
      const float* sheet = sheet_depth.ptr<float>(y);
      const float* zs = shape_depth.ptr<float>(y);
      for (int i = 0; i < gw; ++i) {
        const int x = box.x + kStep * i;
        if (!(z_near < sheet[x]) || !(z_near < zs[x]))
          continue;  // covered: unknown, its neighbours are cast
        auto& l = lattice[static_cast<std::size_t>(j * gw + i)];
        if (!cast(x, y, l.s, l.lambert)) l.s = kInfF;
      }
    }
    const auto at = [&](int i, int j) -> const LatticePoint& {
      return lattice[static_cast<std::size_t>(j * gw + i)];
    };
    // A shape at least 3 cells thick in the image (its thinnest section at its farthest, the focal
    // length less a tenth for the distortion) holds a lattice point in every part of it: a cell
    // whose four corners all miss it is missed but for a sliver at the tip of a silhouette (for a
    // rim of radius R px, less than 2 / R px deep). A thinner one is cast there pixel by pixel.
    const bool thick = 0.9 * std::min(cam.K(0, 0), cam.K(1, 1)) * thickness(sh.geom) >=
                       3.0 * kStep * in_view.z_far;
    // A bounding box wholly above the table's top: no pixel of it is under the table.
    const bool may_dip = sh.pose.t.z - world::half_extent(sh.geom, sh.pose, 2) < drawing.table_z_mm;
    // Cell by cell: the pixels from lattice point (i, j) up to (not including) (i + 1, j + 1);
    // a cell on the rectangle's last row or column (no far corners) is cast pixel by pixel.
    for (int j = 0; j < gh; ++j) {
      const int cy0 = box.y + kStep * j, cy1 = std::min(cy0 + kStep, box.y + box.height);
      for (int i = 0; i < gw; ++i) {
        const int cx0 = box.x + kStep * i, cx1 = std::min(cx0 + kStep, box.x + box.width);
        const bool inner = i + 1 < gw && j + 1 < gh;
        const LatticePoint& a = at(i, j);
        const LatticePoint& b = inner ? at(i + 1, j) : a;
        const LatticePoint& c2 = inner ? at(i, j + 1) : a;
        const LatticePoint& d = inner ? at(i + 1, j + 1) : a;
        // All four met it (NaN, not cast, fails too), or none did.
        const bool all_hit = inner && a.s < kInfF && b.s < kInfF && c2.s < kInfF && d.s < kInfF;
        if (inner && thick && a.s == kInfF && b.s == kInfF && c2.s == kInfF && d.s == kInfF)
          continue;  // a cell the shape does not reach into
        for (int y = cy0; y < cy1; ++y) {
          const float* sheet = sheet_depth.ptr<float>(y);
          float* zs = shape_depth.ptr<float>(y);
          float* px = image.ptr<float>(y);
          std::uint8_t* mk = mask.ptr<std::uint8_t>(y);
          const float wy = static_cast<float>(y - cy0) / kStep;
          for (int x = cx0; x < cx1; ++x) {
            if (!(z_near < sheet[x]) || !(z_near < zs[x])) continue;  // something nearer covers it
            float s = kInfF, lambert = 0;
            if (all_hit) {
              const float wx = static_cast<float>(x - cx0) / kStep;
              const float w00 = (1 - wx) * (1 - wy), w10 = wx * (1 - wy), w01 = (1 - wx) * wy,
                          w11 = wx * wy;
              s = w00 * a.s + w10 * b.s + w01 * c2.s + w11 * d.s;
              lambert = w00 * a.lambert + w10 * b.lambert + w01 * c2.lambert + w11 * d.lambert;
            } else if (!cast(x, y, s, lambert)) {
              continue;
            }
            if (!(s < sheet[x]) || !(s < zs[x])) continue;  // behind the sheet or a nearer shape
            if (may_dip) {
              const cv::Vec2f ray = rays.at<cv::Vec2f>(y, x);
              // The hit's world z: the ray's world z per camera z times s.
              const double dz = rt(2, 0) * ray[0] + rt(2, 1) * ray[1] + rt(2, 2);
              if (c[2] + s * dz < drawing.table_z_mm) continue;  // under the table's top
            }
            zs[x] = s;
            px[x] = static_cast<float>(drawing.skin_grey * (0.5 + 0.5 * lambert));
            mk[x] = 255;
          }
        }
      }
    }
  }
}

}  // namespace crease::vision
